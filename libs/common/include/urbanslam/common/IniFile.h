#pragma once
// The text of an ini file in MRPT's conventions: [section], key = value, comments starting with
// ';', '#' or '//' (whole line or after a value). Only syntax is checked here; what keys mean
// and which are allowed is OptionsSchema's job.
#include <string>
#include <vector>

namespace urbanslam::common {

struct IniEntry {
  std::string section, key, value;
  int line = 0;
};

class IniFile {
 public:
  // Throws ConfigError ("FILE:LINE: ...") on a missing file or a malformed line.
  static IniFile load(const std::string& path);
  static IniFile parse(const std::string& text, const std::string& name);

  const std::string& name() const { return name_; }
  const std::vector<IniEntry>& entries() const { return entries_; }
  const std::vector<std::string>& sections() const { return sections_; }

 private:
  std::string name_;
  std::vector<IniEntry> entries_;
  std::vector<std::string> sections_;
};

}  // namespace urbanslam::common
