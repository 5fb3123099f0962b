#pragma once
// What the simulated city looks like: ini section [city]. The city is a function of these and
// the seed only.
#include <cstdint>

namespace urbanslam::sim {

struct CityOptions {
  int seed = 1;
  double area_km2 = 1.0;                      // square city of this area; streets stop at its edge
  double block_min_m = 60.0;                  // building lots between streets: smallest ...
  double block_max_m = 140.0;                 // ... and largest side
  double street_width_m = 16.0;               // facade to facade: sidewalks, parking lanes, two driving lanes
  double tile_size_m = 200.0;                 // the city is built lazily in square tiles of this side
  double cell_size_m = 4.0;                   // ray-casting grid inside a tile
  int cache_tiles = 64;                       // tiles kept in memory (least recently used ones are dropped)
  double park_probability = 0.05;             // a block is a park (trees)
  double square_probability = 0.04;           // a block is a paved square (fountain, benches, posts)
  double dead_end_probability = 0.06;         // a street piece is closed half-way
  double repeated_design_probability = 0.3;   // a facade is a copy of one of a few designs (aliasing)
  int design_count = 4;                       // how many repeated designs exist
  double featureless_wall_probability = 0.1;  // a facade is a long wall without any detail
  double facade_min_m = 8.0;                  // width of one building along the street: smallest ...
  double facade_max_m = 30.0;                 // ... and largest
  double tree_spacing_m = 12.0;               // mean gap between trees along a sidewalk; 0: no trees
  double tree_probability = 0.5;              // a sidewalk has a row of trees
  double lamp_post_spacing_m = 25.0;          // gap between lamp posts; 0: none
  double parked_car_probability = 0.4;        // a parking slot is taken
  // Diagonal avenues: parallel straight boulevards crossing the grid at one angle (30..60 degrees
  // from the x axis, from the seed), this far apart; 0: none.
  double avenue_spacing_m = 900.0;
  double avenue_width_m = 30.0;             // facade to facade
  double roundabout_probability = 0.08;     // an intersection of the grid is a roundabout
  double roundabout_island_radius_m = 5.0;  // the central island (a kerb the laser sees)
  int buildings_per_block_min = 2;          // separate buildings on one block, with alleys between
  int buildings_per_block_max = 6;
  double alley_width_m = 3.0;           // gap between neighbouring buildings of a block
  double building_setback_max_m = 3.0;  // a building may stand back from the street up to this
};

}  // namespace urbanslam::sim
