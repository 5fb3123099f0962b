#pragma once
// Moving objects: cars in the driving lanes and pedestrians on the sidewalks. They are not part of
// the static map (a SLAM system must cope with them) and, like the city, a pure function of the
// seed and the time: each lane or sidewalk carries a periodic stream whose members are found
// locally, so any time and place can be queried without simulating the traffic.
#include <vector>

#include "urbanslam/sim/Geometry.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/StreetGrid.h"

namespace urbanslam::sim {

// One moving object at one instant, as the outline the laser sees.
struct MovingObject {
  Vec2 centre;
  double radius = 0;  // bounding circle, for culling
  std::vector<Segment> outline;
};

class Traffic {
 public:
  Traffic(const StreetGrid& grid, const TrafficOptions& options);
  // Objects within radius of centre at time t (seconds since the start), leaving out those
  // within the clearance of the ego vehicle (they would drive through it).
  std::vector<MovingObject> near(Vec2 centre, double radius, double t, Vec2 ego) const;

 private:
  const StreetGrid& grid_;
  TrafficOptions options_;
};

}  // namespace urbanslam::sim
