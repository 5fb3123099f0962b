// `urbanslam convert`: any supported log → MRPT rawlog (RawLogViewer, rawlog-edit open it).
#include <iostream>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Progress.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/RawlogWriter.h"

namespace urbanslam::cli {

int convertCommand(const Argv& args) {
  ArgParser ap("urbanslam convert [--layout observations|frames] [--quiet] [--json] IN OUT.rawlog",
               "Writes any supported input (MRPT rawlog, CARMEN log, GMapping gfs log, Victoria Park folder/zip)\n"
               "as an MRPT rawlog, keeping timestamps. Speed+steering become CObservationRawDAQ 'DRIVE' {speed, steering},\n"
               "GPS and reference poses CObservationRobotPose 'GPS_LOCAL' / 'REFERENCE'.");
  ap.addPositional("IN", "input log");
  ap.addPositional("OUT", "output rawlog (gzip-compressed)");
  ap.addOption("layout", "L", "observations (one observation per entry) or frames (action/sensory-frame pairs)", "observations");
  ap.addFlag("quiet", "no progress bar");
  ap.addFlag("json", "print counts as one JSON object");
  if (!ap.parse(args)) return 0;
  const std::string layout = ap.option("layout");
  if (layout != "observations" && layout != "frames")
    throw common::InputError("--layout: '" + layout + "' is not one of observations|frames");

  auto source = io::openDataSource(ap.positional("IN"));
  io::RawlogWriter writer(ap.positional("OUT"), layout == "frames" ? io::RawlogLayout::SensoryFrames : io::RawlogLayout::Observations);
  common::ProgressBar bar("convert", 1000, !ap.flag("quiet"));
  io::Measurement m;
  size_t scans = 0, odometry = 0, other = 0;
  while (source->next(m)) {
    writer.write(m);
    if (std::holds_alternative<io::LaserScan>(m))
      ++scans;
    else if (std::holds_alternative<io::OdometryReading>(m))
      ++odometry;
    else
      ++other;
    bar.update(static_cast<uint64_t>(source->progress() * 1000));
  }
  writer.close();
  bar.finish();
  common::Json j = common::Json::object();
  j["input"] = ap.positional("IN");
  j["input_format"] = source->format();
  j["output"] = ap.positional("OUT");
  j["layout"] = layout;
  j["measurements"] = writer.written();
  j["scans"] = scans;
  j["odometry"] = odometry;
  j["other"] = other;
  if (ap.flag("json"))
    std::cout << j.dump() << "\n";
  else
    std::cout << "wrote " << ap.positional("OUT") << ": " << writer.written() << " measurements (" << scans << " scans, " << odometry
              << " odometry, " << other << " other) from " << source->format() << "\n";
  return 0;
}

}  // namespace urbanslam::cli
