#pragma once
// Options validated at load (as Cartographer does): every module declares its option members
// with unit, range and documentation; loading an ini rejects an unknown or misspelled key, a
// missing required key and an out-of-range value with an error naming file, section and key.
// The same declarations print the resolved configuration (check-ini, config.ini beside outputs).
#include <functional>
#include <utility>
#include <string>
#include <vector>

#include "urbanslam/common/Json.h"

namespace urbanslam::common {

class IniFile;

class OptionsSchema {
 public:
  // Subsequent add() calls go into this section.
  void section(const std::string& name, const std::string& doc);

  void add(const std::string& key, double& value, double min, double max, const std::string& unit, const std::string& doc,
           bool required = false);
  void add(const std::string& key, int& value, int min, int max, const std::string& unit, const std::string& doc, bool required = false);
  void add(const std::string& key, bool& value, const std::string& doc, bool required = false);
  // choices empty: any string (e.g. a path).
  void add(const std::string& key, std::string& value, const std::vector<std::string>& choices, const std::string& doc,
           bool required = false);

  // An enum option: the ini holds one of the names, the program compares enum values (never
  // strings at run time).
  template <typename E>
  void add(const std::string& key, E& value, const std::vector<std::pair<std::string, E>>& names, const std::string& doc,
           bool required = false) {
    std::string range;
    for (const auto& n : names) range += (range.empty() ? "" : "|") + n.first;
    Option& o = push(key, "", range, doc, required);
    o.set = [&value, names, range](const std::string& s, const std::string& where) {
      for (const auto& n : names)
        if (n.first == s) {
          value = n.second;
          return;
        }
      throwNotOneOf(where, s, range);
    };
    o.get = [&value, names] {
      for (const auto& n : names)
        if (n.second == value) return n.first;
      return std::string();
    };
  }

  // Applies the ini on top of the current values. Throws ConfigError.
  void load(const IniFile& ini);
  // Resolved configuration as an ini text (every key, with its unit, range and doc).
  std::string toIni() const;
  Json toJson() const;

  struct Option {
    std::string section, key, unit, range, doc;
    bool required = false;
    std::function<void(const std::string& value, const std::string& where)> set;
    std::function<std::string()> get;
  };
  struct Section {
    std::string name, doc;
  };
  const std::vector<Option>& options() const { return options_; }
  const std::vector<Section>& sections() const { return sections_; }

 private:
  [[noreturn]] static void throwNotOneOf(const std::string& where, const std::string& value, const std::string& range);
  Option& push(const std::string& key, const std::string& unit, const std::string& range, const std::string& doc, bool required);

  std::vector<Section> sections_;
  std::vector<Option> options_;
};

}  // namespace urbanslam::common
