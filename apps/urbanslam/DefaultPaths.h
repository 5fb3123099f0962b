#pragma once
// Where the shipped files live: $URBANSLAM_HOME when set, else the source tree this binary was
// built from (the repo is the installation; there is no `make install` yet).
#include <cstdlib>
#include <string>

namespace urbanslam::cli {

inline std::string projectHome() {
  if (const char* h = std::getenv("URBANSLAM_HOME"); h && *h) return h;
  return URBANSLAM_SOURCE_DIR;
}
inline std::string defaultRawlog() { return projectHome() + "/rawlogs/intel.rawlog"; }
inline std::string defaultIni() { return projectHome() + "/ini/default.ini"; }

}  // namespace urbanslam::cli
