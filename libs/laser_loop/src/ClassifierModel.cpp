#include "urbanslam/laser_loop/ClassifierModel.h"

#include "urbanslam/laser_loop/Comparisons.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Numbers.h"

namespace urbanslam::laser_loop {

namespace {

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream is(line);
  std::string w;
  while (is >> w) out.push_back(w);
  return out;
}

class Parser {
 public:
  explicit Parser(std::string source) : source_(std::move(source)) {}
  [[noreturn]] void fail(size_t line, const std::string& msg) const {
    throw common::InputError(source_ + ":" + std::to_string(line) + ": " + msg);
  }
  double number(const std::string& s, size_t line, const std::string& what) const {
    const auto v = common::parseDecimal(s);
    if (!v) fail(line, what + ": '" + s + "' is not a finite number");
    if (std::abs(*v) > common::kMaxMagnitude) fail(line, what + ": " + s + " is out of range (|value| > 1e12)");
    return *v;
  }
  long integer(const std::string& s, size_t line, const std::string& what) const {
    const double v = number(s, line, what);
    if (v != std::floor(v) || v < 0 || v > 1e9) fail(line, what + ": '" + s + "' is not a non-negative integer");
    return static_cast<long>(v);
  }

 private:
  std::string source_;
};

}  // namespace

std::string ClassifierModel::provenanceValue(const std::string& key) const {
  for (const auto& [k, v] : provenance)
    if (k == key) return v;
  return {};
}

std::string modelToText(const ClassifierModel& m) {
  std::ostringstream os;
  os << kModelMagic << " " << kModelFormatVersion << "\n";
  for (const auto& c : m.comments) {
    std::string line = c;
    for (auto& ch : line)
      if (ch == '\n' || ch == '\r') ch = ' ';
    os << "# " << line << "\n";
  }
  os << "r_max_m " << num(m.params.r_max_m) << "\n";
  os << "g_max_dist_m " << num(m.params.g_max_dist_m) << "\n";
  os << "g_min_size " << m.params.g_min_size << "\n";
  os << "beam_increment_deg " << num(m.params.beam_increment_deg) << "\n";
  os << "log_features " << (m.params.log_features ? 1 : 0) << "\n";
  os << "submap_window_m " << num(m.submap_window_m) << "\n";
  os << "factor " << num(m.factor) << "\n";
  for (const auto& [k, v] : m.provenance) {
    std::string value = v;
    for (auto& ch : value)
      if (ch == '\n' || ch == '\r') ch = ' ';
    os << "provenance " << k << " " << value << "\n";
  }
  os << "features " << kFeatureCount;
  for (int i = 0; i < kFeatureCount; ++i) os << " " << featureName(i);
  os << "\n";
  os << "stumps " << m.classifier.size() << "\n";
  for (const auto& s : m.classifier.stumps())
    os << "stump " << comparisonName(s.stump.comparison) << " " << num(s.stump.threshold) << " " << (s.stump.polarity > 0 ? "+1" : "-1")
       << " " << num(s.alpha) << "\n";
  os << "end\n";
  return os.str();
}

void saveModel(const ClassifierModel& model, const std::string& path) {
  common::AtomicFile f(path);
  f.stream() << modelToText(model);
  f.commit();
}

ClassifierModel loadModel(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw common::InputError(path + ": cannot open laser loop-closure model");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parseModel(ss.str(), path);
}

ClassifierModel parseModel(const std::string& text, const std::string& source) {
  Parser p(source);
  ClassifierModel m;
  std::istringstream in(text);
  std::string line;
  size_t ln = 0;
  bool have_magic = false, have_features = false, have_end = false;
  int listed_features = 0;
  bool have_r = false, have_g = false, have_s = false, have_b = false, have_factor = false;
  long declared_stumps = -1;
  std::vector<WeightedStump> stumps;
  while (std::getline(in, line)) {
    ++ln;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (have_end) {
      if (!split(line).empty()) p.fail(ln, "text after 'end'");
      continue;
    }
    if (!have_magic) {
      const auto f = split(line);
      if (f.size() != 2 || f[0] != kModelMagic)
        p.fail(ln, std::string("not a laser loop-closure model (expected '") + kModelMagic + " <version>' on the first line)");
      const long v = p.integer(f[1], ln, "format version");
      if (v != kModelFormatVersion)
        p.fail(ln,
               "model format version " + f[1] + " is not supported (this build reads version " + std::to_string(kModelFormatVersion) + ")");
      have_magic = true;
      continue;
    }
    if (!line.empty() && line[0] == '#') {
      // saveModel writes "# " + comment: a bare "#" is an empty comment, as "# " is.
      m.comments.push_back(line.size() >= 2 && line[1] == ' ' ? line.substr(2) : line.substr(1));
      continue;
    }
    const auto f = split(line);
    if (f.empty()) continue;
    const std::string& key = f[0];
    auto need = [&](size_t n) {
      if (f.size() != n) p.fail(ln, "'" + key + "' takes " + std::to_string(n - 1) + " value(s), got " + std::to_string(f.size() - 1));
    };
    if (key == "r_max_m") {
      need(2);
      m.params.r_max_m = p.number(f[1], ln, key);
      if (m.params.r_max_m <= 0) p.fail(ln, "r_max_m must be > 0");
      have_r = true;
    } else if (key == "g_max_dist_m") {
      need(2);
      m.params.g_max_dist_m = p.number(f[1], ln, key);
      if (m.params.g_max_dist_m <= 0) p.fail(ln, "g_max_dist_m must be > 0");
      have_g = true;
    } else if (key == "g_min_size") {
      need(2);
      m.params.g_min_size = static_cast<int>(p.integer(f[1], ln, key));
      have_s = true;
    } else if (key == "beam_increment_deg") {
      need(2);
      m.params.beam_increment_deg = p.number(f[1], ln, key);
      if (m.params.beam_increment_deg < 0) p.fail(ln, "beam_increment_deg must be >= 0");
      have_b = true;
    } else if (key == "log_features") {
      // Optional: models written before the option existed compare the plain features.
      need(2);
      if (f[1] == "1")
        m.params.log_features = true;
      else if (f[1] == "0")
        m.params.log_features = false;
      else
        p.fail(ln, "log_features must be 0 or 1, got '" + f[1] + "'");
    } else if (key == "submap_window_m") {
      // Optional: models written before the option existed use each scan alone.
      need(2);
      m.submap_window_m = p.number(f[1], ln, key);
      if (m.submap_window_m < 0) p.fail(ln, "submap_window_m must be >= 0");
    } else if (key == "factor") {
      need(2);
      m.factor = p.number(f[1], ln, key);
      have_factor = true;
    } else if (key == "provenance") {
      if (f.size() < 2) p.fail(ln, "'provenance' needs a key");
      const size_t at = line.find(f[1], line.find("provenance") + 10) + f[1].size();
      std::string value = at < line.size() ? line.substr(at) : "";
      // The white space that separates the fields (split: istream's, isspace), so a value that
      // starts with a carriage return or form feed reads back the same after saveModel.
      value.erase(0, value.find_first_not_of(" \t\n\v\f\r"));
      m.provenance.emplace_back(f[1], value);
    } else if (key == "features") {
      if (f.size() < 2) p.fail(ln, "'features' needs a count");
      const long n = p.integer(f[1], ln, "feature count");
      // A model lists the features of the build that trained it. Features are only ever appended
      // (the thesis's twenty first), so an older model's list is a prefix of this build's.
      if (n < 1 || n > kFeatureCount || f.size() != static_cast<size_t>(n) + 2)
        p.fail(ln, "the model has " + f[1] + " features; this build computes " + std::to_string(kFeatureCount));
      for (int i = 0; i < n; ++i)
        if (f[static_cast<size_t>(i) + 2] != featureName(i))
          p.fail(ln, "feature " + std::to_string(i) + " is '" + f[static_cast<size_t>(i) + 2] + "', this build has '" + featureName(i) +
                         "' (a model from a different feature set)");
      have_features = true;
      listed_features = static_cast<int>(n);
    } else if (key == "stumps") {
      need(2);
      declared_stumps = p.integer(f[1], ln, "stump count");
    } else if (key == "stump") {
      if (declared_stumps < 0) p.fail(ln, "'stump' before 'stumps <count>'");
      need(5);
      WeightedStump s;
      s.stump.comparison = comparisonIndex(f[1]);
      if (s.stump.comparison < 0) p.fail(ln, "unknown feature or distance '" + f[1] + "'");
      s.stump.threshold = p.number(f[2], ln, "threshold");
      if (f[3] == "+1" || f[3] == "1")
        s.stump.polarity = 1;
      else if (f[3] == "-1")
        s.stump.polarity = -1;
      else
        p.fail(ln, "polarity must be +1 or -1, got '" + f[3] + "'");
      s.alpha = p.number(f[4], ln, "alpha");
      if (s.alpha < 0) p.fail(ln, "alpha must be >= 0");
      stumps.push_back(s);
    } else if (key == "end") {
      need(1);
      have_end = true;
    } else {
      p.fail(ln, "unknown key '" + key + "'");
    }
  }
  if (!have_magic) p.fail(1, "empty file (not a laser loop-closure model)");
  if (!have_end) p.fail(ln, "no 'end' line: the file is truncated");
  std::string missing;
  if (!have_r) missing += " r_max_m";
  if (!have_g) missing += " g_max_dist_m";
  if (!have_s) missing += " g_min_size";
  if (!have_b) missing += " beam_increment_deg";
  if (!have_factor) missing += " factor";
  if (!have_features) missing += " features";
  if (declared_stumps < 0) missing += " stumps";
  if (!missing.empty()) p.fail(ln, "missing required key(s):" + missing);
  if (static_cast<long>(stumps.size()) != declared_stumps)
    p.fail(ln, "'stumps " + std::to_string(declared_stumps) + "' declared but " + std::to_string(stumps.size()) + " stump lines found");
  if (stumps.empty()) p.fail(ln, "the model has no stumps");
  for (const auto& s : stumps) {
    const int k = s.stump.comparison;
    int needs = k + 1;
    if (k >= kFeatureCount) {
      const FeatureRange r = distanceFeatures(static_cast<Distance>(k - kFeatureCount));
      needs = r.begin + r.count;
    }
    if (needs > listed_features)
      p.fail(ln, std::string("stump on '") + comparisonName(k) + "', which needs features the model's 'features' line does not list");
  }
  m.classifier = StrongClassifier(std::move(stumps));
  return m;
}

}  // namespace urbanslam::laser_loop
