#pragma once
// Procedural textures of the city's surfaces: grey value as a pure function of the look (id,
// kind, height) and a point on the surface (u_m along it, h_m above the ground). Facades get
// floors of framed windows with blinds and lit rooms, shop fronts with signs of pseudo-letters,
// doors, pilasters, string courses, a cornice and a wall material (blocks, panels or plaster):
// structure at the scale of 0.1-3 m, so an image feature detector finds many corners and blobs
// that stay put when the viewpoint changes. Finer detail is kept weak, because nearest-texel
// sampling would turn it into viewpoint-dependent aliasing. A repeated design has one id, so
// its copies look the same (perceptual aliasing, as in real streets).
//
// Sampling is split into a column part (everything that depends on u only) and a row part, so a
// renderer drawing vertical strips pays the u work once per image column.
#include <cstdint>

#include "urbanslam/sim/Geometry.h"

namespace urbanslam::sim {

// How tall a surface of this look stands: a whole number of floors plus the cornice for a
// facade; a plausible size for everything else. Used by the city generator to set the look.
double facadeHeight(uint32_t id, SurfaceKind kind);

class SurfaceTexture {
 public:
  explicit SurfaceTexture(const SurfaceLook& look);

  // What a vertical line of the surface at u needs, computed once.
  struct Column {
    double u = 0;
    int bay = 0;           // window bay index along the facade
    double bay_u = 0;      // position inside the bay [0, bay width)
    bool window = false;   // inside a window opening (horizontally) ...
    bool frame = false;    // ... and on its frame
    bool mullion = false;  // on the window's vertical bar
    bool pilaster = false;
    bool door = false;  // ground floor door opening
    int letter = 0;     // sign letter index and the bit column inside it (-1: gap)
    int letter_col = -1;
    int shop = 0;                       // shop front index (its own sign colours)
    int block_even = 0, block_odd = 0;  // wall material block index in even / odd courses
    double block_u_even = 0, block_u_odd = 0;
    uint64_t coarse = 0;  // hash of the coarse u cell (stains, bark, panels)
  };
  Column column(double u_m) const;
  // Grey value 0-255 (before shading and fog) at height h_m of a column.
  uint8_t at(const Column& c, double h_m) const;
  uint8_t sample(double u_m, double h_m) const { return at(column(u_m), h_m); }

  const SurfaceLook& look() const { return look_; }
  double floorHeight() const { return floor_h_; }
  double groundFloorHeight() const { return ground_h_; }
  double corniceHeight() const { return cornice_h_; }

 private:
  uint8_t facade(const Column& c, double h) const;
  uint8_t material(const Column& c, double h) const;

  SurfaceLook look_;
  // Facade layout (metres) and tones (grey levels), drawn from the look's id.
  double floor_h_ = 3, ground_h_ = 4, bay_w_ = 3, bay_off_ = 0, win_w_ = 1.4, win_h_ = 1.6, sill_ = 0.9;
  double frame_w_ = 0.1, cornice_h_ = 0.8, block_h_ = 0.35, block_w_ = 0.7;
  int pilaster_every_ = 0, material_ = 0, shop_bays_ = 2, door_every_ = 3;
  bool shops_ = true, mullions_ = true;
  int wall_ = 150, frame_tone_ = 40, glass_ = 50, accent_ = 100, cornice_tone_ = 200;
};

}  // namespace urbanslam::sim
