#include "urbanslam/common/OptionsSchema.h"

#include <cmath>
#include <sstream>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/IniFile.h"
#include "urbanslam/common/Numbers.h"

namespace urbanslam::common {

namespace {

std::string formatDouble(double v) {
  std::ostringstream os;
  os.precision(12);
  os << v;
  return os.str();
}

double parseDouble(const std::string& s, const std::string& where) {
  const auto v = parseDecimal(s);
  if (!v) throw ConfigError(where + "'" + s + "' is not a number (plain decimal; hex, inf and NaN are not accepted)");
  return *v;
}

long parseInt(const std::string& s, const std::string& where) {
  const auto v = parseWholeNumber(s);
  if (!v) throw ConfigError(where + "'" + s + "' is not a whole number");
  return *v;
}

}  // namespace

void OptionsSchema::section(const std::string& name, const std::string& doc) { sections_.push_back({name, doc}); }

OptionsSchema::Option& OptionsSchema::push(const std::string& key, const std::string& unit, const std::string& range,
                                           const std::string& doc, bool required) {
  if (sections_.empty()) throw std::logic_error("OptionsSchema: add() before section()");
  Option o;
  o.section = sections_.back().name;
  o.key = key;
  o.unit = unit;
  o.range = range;
  o.doc = doc;
  o.required = required;
  options_.push_back(std::move(o));
  return options_.back();
}

void OptionsSchema::add(const std::string& key, double& value, double min, double max, const std::string& unit, const std::string& doc,
                        bool required) {
  Option& o = push(key, unit, "[" + formatDouble(min) + ", " + formatDouble(max) + "]", doc, required);
  o.set = [&value, min, max](const std::string& s, const std::string& where) {
    const double v = parseDouble(s, where);
    if (v < min || v > max) throw ConfigError(where + s + " is out of range [" + formatDouble(min) + ", " + formatDouble(max) + "]");
    value = v;
  };
  o.get = [&value] { return formatDouble(value); };
}

void OptionsSchema::add(const std::string& key, int& value, int min, int max, const std::string& unit, const std::string& doc,
                        bool required) {
  Option& o = push(key, unit, "[" + std::to_string(min) + ", " + std::to_string(max) + "]", doc, required);
  o.set = [&value, min, max](const std::string& s, const std::string& where) {
    const long v = parseInt(s, where);
    if (v < min || v > max) throw ConfigError(where + s + " is out of range [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    value = static_cast<int>(v);
  };
  o.get = [&value] { return std::to_string(value); };
}

void OptionsSchema::add(const std::string& key, bool& value, const std::string& doc, bool required) {
  Option& o = push(key, "", "true|false", doc, required);
  o.set = [&value](const std::string& s, const std::string& where) {
    if (s == "1" || s == "true" || s == "yes" || s == "on")
      value = true;
    else if (s == "0" || s == "false" || s == "no" || s == "off")
      value = false;
    else
      throw ConfigError(where + "'" + s + "' is not a boolean (true/false/1/0)");
  };
  o.get = [&value] { return std::string(value ? "true" : "false"); };
}

void OptionsSchema::add(const std::string& key, std::string& value, const std::vector<std::string>& choices, const std::string& doc,
                        bool required) {
  std::string range;
  for (const auto& c : choices) range += (range.empty() ? "" : "|") + c;
  Option& o = push(key, "", range.empty() ? "text" : range, doc, required);
  o.set = [&value, choices, range](const std::string& s, const std::string& where) {
    if (!choices.empty()) {
      bool ok = false;
      for (const auto& c : choices) ok = ok || c == s;
      if (!ok) throwNotOneOf(where, s, range);
    }
    value = s;
  };
  o.get = [&value] { return value; };
}

void OptionsSchema::throwNotOneOf(const std::string& where, const std::string& value, const std::string& range) {
  throw ConfigError(where + "'" + value + "' is not one of " + range);
}

void OptionsSchema::load(const IniFile& ini) {
  for (const auto& s : ini.sections()) {
    bool known = false;
    for (const auto& d : sections_) known = known || d.name == s;
    if (!known) {
      std::string list;
      for (const auto& d : sections_) list += (list.empty() ? "" : ", ") + ("[" + d.name + "]");
      throw ConfigError(ini.name() + ": unknown section [" + s + "] (known: " + list + ")");
    }
  }
  for (const auto& e : ini.entries()) {
    const std::string where = ini.name() + ":" + std::to_string(e.line) + ": [" + e.section + "] " + e.key + ": ";
    Option* match = nullptr;
    for (auto& o : options_)
      if (o.section == e.section && o.key == e.key) match = &o;
    if (!match) {
      std::string hint;
      for (const auto& o : options_)
        if (o.section == e.section) hint += (hint.empty() ? "" : ", ") + o.key;
      throw ConfigError(ini.name() + ":" + std::to_string(e.line) + ": [" + e.section + "] " + e.key +
                        ": unknown key (keys of this section: " + hint + ")");
    }
    match->set(e.value, where);
  }
  for (const auto& o : options_) {
    if (!o.required) continue;
    bool given = false;
    for (const auto& e : ini.entries()) given = given || (e.section == o.section && e.key == o.key);
    if (!given) throw ConfigError(ini.name() + ": [" + o.section + "] " + o.key + ": required key is missing");
  }
}

std::string OptionsSchema::toIni() const {
  std::ostringstream os;
  for (const auto& s : sections_) {
    os << "\n// " << s.doc << "\n[" << s.name << "]\n";
    for (const auto& o : options_) {
      if (o.section != s.name) continue;
      std::string comment = o.doc;
      if (!o.unit.empty()) comment += " [" + o.unit + "]";
      comment += " range " + o.range;
      if (o.required) comment += " (required)";
      std::string kv = o.key + " = " + o.get();
      if (kv.size() < 36) kv.append(36 - kv.size(), ' ');
      os << kv << " // " << comment << "\n";
    }
  }
  return os.str();
}

Json OptionsSchema::toJson() const {
  Json j = Json::object();
  for (const auto& s : sections_) {
    Json& sec = j[s.name];
    sec = Json::object();
    for (const auto& o : options_)
      if (o.section == s.name) sec[o.key] = o.get();
  }
  return j;
}

}  // namespace urbanslam::common
