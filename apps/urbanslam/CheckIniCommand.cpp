// `urbanslam check-ini`: validates an ini as `run` would and prints the resolved configuration.
#include <algorithm>
#include <iostream>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/common/IniFile.h"
#include "urbanslam/common/OptionsSchema.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/slam/PipelineOptions.h"

namespace urbanslam::cli {

int checkIniCommand(const Argv& args) {
  ArgParser ap("urbanslam check-ini [--json] FILE",
               "Validates FILE (unknown or misspelled keys, missing required keys and out-of-range\n"
               "values are errors naming file, section and key) and prints the resolved configuration:\n"
               "every key with its value, unit, range and meaning. FILE is a run configuration, or a\n"
               "simulation configuration when it has a [city] section.");
  ap.addPositional("FILE", "ini file to check");
  ap.addFlag("json", "print the resolved configuration as one JSON object");
  if (!ap.parse(args)) return 0;
  std::string resolved;
  // A city ini (for `simulate` and `run --simulate`) is told apart by its [city] section.
  const auto sections = common::IniFile::load(ap.positional("FILE")).sections();
  if (std::find(sections.begin(), sections.end(), "city") != sections.end()) {
    common::OptionsSchema schema;
    sim::SimOptions so = sim::loadSimOptions(ap.positional("FILE"), &resolved);
    sim::declareSimOptions(schema, so);
    if (ap.flag("json"))
      std::cout << schema.toJson().dump() << "\n";
    else
      std::cout << "// " << ap.positional("FILE") << ": OK (simulation). Resolved configuration:\n" << resolved;
    return 0;
  }
  const slam::PipelineOptions o = slam::loadPipelineOptions(ap.positional("FILE"), &resolved);
  if (ap.flag("json")) {
    std::cout << slam::optionsToJson(o).dump() << "\n";
  } else {
    std::cout << "// " << ap.positional("FILE") << ": OK. Resolved configuration:\n" << resolved;
  }
  return 0;
}

}  // namespace urbanslam::cli
