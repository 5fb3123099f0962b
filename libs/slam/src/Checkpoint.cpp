#include "urbanslam/slam/Checkpoint.h"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>

#include "urbanslam/common/AtomicFolder.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/IniFile.h"
#include "urbanslam/slam/MapFile.h"

namespace urbanslam::slam {

namespace fs = std::filesystem;

namespace {

constexpr const char* kInfoFile = "checkpoint.ini";
constexpr const char* kInfoHeader = "; urbanslam checkpoint";

bool isCheckpointFolder(const std::string& dir) {
  return common::isReplaceableOutputFolder(dir, kInfoFile, [](const std::string& first) { return first.rfind(kInfoHeader, 0) == 0; });
}

std::uint64_t toCount(const std::map<std::string, std::string>& kv, const std::string& key, const std::string& file) {
  const auto it = kv.find(key);
  if (it == kv.end()) throw common::InputError(file + ": no [checkpoint] " + key + " (an incomplete checkpoint)");
  try {
    size_t used = 0;
    const unsigned long long v = std::stoull(it->second, &used);
    if (used == it->second.size()) return v;
  } catch (const std::exception&) {
  }
  throw common::InputError(file + ": [checkpoint] " + key + " = " + it->second + " is not a count");
}

double toNonNegative(const std::map<std::string, std::string>& kv, const std::string& key, const std::string& file) {
  const auto it = kv.find(key);
  if (it == kv.end()) throw common::InputError(file + ": no [checkpoint] " + key + " (an incomplete checkpoint)");
  try {
    size_t used = 0;
    const double v = std::stod(it->second, &used);
    if (used == it->second.size() && v >= 0) return v;
  } catch (const std::exception&) {
  }
  throw common::InputError(file + ": " + key + " = " + it->second + " is not a number of at least 0");
}

// The same file named twice (a relative and an absolute path, a symbolic link).
bool sameFile(const std::string& a, const std::string& b) {
  std::error_code ea, eb;
  const fs::path ca = fs::weakly_canonical(a, ea), cb = fs::weakly_canonical(b, eb);
  return ea || eb ? a == b : ca == cb;
}

}  // namespace

std::string checkpointPath(const std::string& out) {
  std::string o = out;
  while (o.size() > 1 && o.back() == '/') o.pop_back();
  return o + ".checkpoint";
}

void saveCheckpoint(const Pipeline& pipeline, const std::string& dir, const CheckpointInfo& info) {
  common::AtomicFolder folder(dir, isCheckpointFolder);
  const fs::path staging(folder.stagingPath());
  writeMapFile(pipeline, (staging / kMapFileName).string());
  {
    std::ofstream f(staging / kInfoFile);
    f << kInfoHeader << ": a run's map and how far it read its input (`urbanslam run --continue`)\n"
      << "[checkpoint]\n"
      << "input = " << info.input << "\n"
      << "input_measurements = " << info.input_measurements << "\n"
      << "keyframes = " << info.keyframes << "\n"
      << std::setprecision(17) << "cpu_s = " << info.cpu_s << "\n"
      << "wall_s = " << info.wall_s << "\n"
      << "resumed_map = " << info.resumed_map << "\n"
      << "[counters]\n";
    for (const auto& [key, value] : info.counters) f << key << " = " << value << "\n";
    f.flush();
    if (!f) throw common::InputError(dir + ": cannot write " + kInfoFile + " (disk full?)");
  }
  folder.commit();
}

Checkpoint loadCheckpoint(const std::string& dir, const PipelineOptions* options, const std::string& input) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw common::InputError(dir + ": no checkpoint here (a run saves one with --checkpoint-every)");
  const std::string file = (fs::path(dir) / kInfoFile).string();
  if (!fs::exists(file, ec)) throw common::InputError(dir + ": a folder without " + kInfoFile + " (not a checkpoint)");
  std::map<std::string, std::string> kv;
  const common::IniFile ini = common::IniFile::load(file);
  std::map<std::string, std::string> counters;
  for (const auto& e : ini.entries()) (e.section == "checkpoint" ? kv : counters)[e.key] = e.value;
  Checkpoint c;
  for (const auto& [key, value] : counters) c.info.counters[key] = toNonNegative(counters, key, file);
  c.info.input = kv.count("input") ? kv["input"] : "";
  if (c.info.input.empty()) throw common::InputError(file + ": no [checkpoint] input (an incomplete checkpoint)");
  if (!input.empty() && !sameFile(c.info.input, input))
    throw common::InputError(dir + ": made from " + c.info.input + ", not from " + input + " (continue it with that input)");
  c.info.input_measurements = toCount(kv, "input_measurements", file);
  c.info.keyframes = toCount(kv, "keyframes", file);
  c.info.cpu_s = toNonNegative(kv, "cpu_s", file);
  c.info.wall_s = toNonNegative(kv, "wall_s", file);
  c.info.resumed_map = kv.count("resumed_map") ? kv["resumed_map"] : "";
  c.pipeline = loadMap((fs::path(dir) / kMapFileName).string(), options);
  if (c.pipeline->keyframes().size() != c.info.keyframes || c.pipeline->stats().measurements < c.info.input_measurements)
    throw common::InputError(dir + ": its map (" + std::to_string(c.pipeline->keyframes().size()) + " keyframes) is not the one " +
                             kInfoFile + " describes (" + std::to_string(c.info.keyframes) + ")");
  return c;
}

void skipMeasurements(io::DataSource& source, std::uint64_t n, const std::string& name) {
  io::Measurement m;
  for (std::uint64_t i = 0; i < n; ++i)
    if (!source.next(m))
      throw common::InputError(name + ": ends after " + std::to_string(i) + " measurements, before the checkpoint's " + std::to_string(n) +
                               " (not the input the checkpoint was made from)");
}

Checkpointer::Checkpointer(std::string dir, size_t every_keyframes, CheckpointInfo earlier, std::uint64_t start_measurements)
    : dir_(std::move(dir)),
      every_(every_keyframes),
      earlier_(std::move(earlier)),
      start_measurements_(start_measurements),
      last_keyframes_(earlier_.keyframes),
      cpu0_(common::processCpuSeconds()) {}

bool Checkpointer::afterStep(Pipeline& pipeline, const io::DataSource& source) {
  const size_t k = pipeline.keyframesMade();
  if (every_ == 0 || k < last_keyframes_ + every_) return false;
  save(pipeline, source);
  return true;
}

void Checkpointer::save(Pipeline& pipeline, const io::DataSource& source) {
  pipeline.waitForGlobalSlam(source);  // what the counters and the map hold is then the same keyframes'
  CheckpointInfo info = earlier_;
  if (counters_) info.counters = counters_();
  info.input_measurements = pipeline.stats().measurements - start_measurements_;
  info.keyframes = pipeline.keyframesMade();
  info.cpu_s = cpuSeconds();
  info.wall_s = wallSeconds();
  saveCheckpoint(pipeline, dir_, info);
  last_keyframes_ = info.keyframes;
  ++saved_;
}

void runCheckpointed(Pipeline& pipeline, io::DataSource& source, Checkpointer& saver) {
  while (pipeline.step(source)) saver.afterStep(pipeline, source);
  pipeline.waitForGlobalSlam(source);
}

double Checkpointer::cpuSeconds() const { return earlier_.cpu_s + common::processCpuSeconds() - cpu0_; }
double Checkpointer::wallSeconds() const { return earlier_.wall_s + wall_.seconds(); }

}  // namespace urbanslam::slam
