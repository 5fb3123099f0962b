#include "urbanslam/common/IniFile.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "urbanslam/common/Error.h"

namespace urbanslam::common {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// Removes a trailing comment: '//' anywhere, or ';' / '#' at the start or after white space.
std::string stripComment(const std::string& s) {
  size_t cut = s.find("//");
  for (size_t i = 0; i < s.size() && i < cut; ++i) {
    if ((s[i] == ';' || s[i] == '#') && (i == 0 || s[i - 1] == ' ' || s[i - 1] == '\t')) {
      cut = i;
      break;
    }
  }
  return cut == std::string::npos ? s : s.substr(0, cut);
}

}  // namespace

IniFile IniFile::load(const std::string& path) {
  // An ifstream opens a directory and reads it as empty: that would be an ini of defaults.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw ConfigError(path + ": is a directory, not an ini file");
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open the ini file");
  std::stringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw ConfigError(path + ": cannot read the ini file");
  return parse(ss.str(), path);
}

IniFile IniFile::parse(const std::string& text, const std::string& name) {
  IniFile ini;
  ini.name_ = name;
  std::istringstream in(text);
  std::string raw, section;
  int lineNo = 0;
  while (std::getline(in, raw)) {
    ++lineNo;
    const std::string line = trim(stripComment(raw));
    if (line.empty()) continue;
    const std::string where = name + ":" + std::to_string(lineNo) + ": ";
    if (line.front() == '[') {
      if (line.back() != ']') throw ConfigError(where + "malformed section header '" + line + "'");
      section = trim(line.substr(1, line.size() - 2));
      if (section.empty()) throw ConfigError(where + "empty section name");
      if (std::find(ini.sections_.begin(), ini.sections_.end(), section) != ini.sections_.end())
        throw ConfigError(where + "section [" + section + "] appears twice");
      ini.sections_.push_back(section);
      continue;
    }
    const auto eq = line.find('=');
    if (eq == std::string::npos) throw ConfigError(where + "expected 'key = value', got '" + line + "'");
    if (section.empty()) throw ConfigError(where + "key outside of any [section]");
    IniEntry e{section, trim(line.substr(0, eq)), trim(line.substr(eq + 1)), lineNo};
    if (e.key.empty()) throw ConfigError(where + "empty key");
    for (const auto& other : ini.entries_)
      if (other.section == e.section && other.key == e.key)
        throw ConfigError(where + "[" + section + "] " + e.key + " is set twice (first on line " + std::to_string(other.line) + ")");
    ini.entries_.push_back(std::move(e));
  }
  return ini;
}

}  // namespace urbanslam::common
