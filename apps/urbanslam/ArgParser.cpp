#include "ArgParser.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "urbanslam/common/Error.h"

namespace urbanslam::cli {

using common::InputError;

ArgParser::ArgParser(std::string usage, std::string summary) : usage_(std::move(usage)), summary_(std::move(summary)) {}

void ArgParser::addFlag(const std::string& name, const std::string& help) { opts_.push_back({name, "", help, "", true}); }

void ArgParser::addOption(const std::string& name, const std::string& metavar, const std::string& help, const std::string& default_value) {
  opts_.push_back({name, metavar, help, default_value, false});
}

void ArgParser::addPositional(const std::string& name, const std::string& help, bool required, bool variadic) {
  pos_.push_back({name, help, required, variadic});
}

const ArgParser::Opt* ArgParser::findOpt(const std::string& name) const {
  for (const auto& o : opts_)
    if (o.name == name) return &o;
  return nullptr;
}

bool ArgParser::parse(const std::vector<std::string>& args) {
  std::vector<std::string> positional;
  bool only_positional = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (!only_positional && (a == "--help" || a == "-h")) {
      std::cout << helpText();
      return false;
    }
    if (!only_positional && a == "--") {
      only_positional = true;
      continue;
    }
    if (!only_positional && a.size() > 2 && a.compare(0, 2, "--") == 0) {
      std::string name = a.substr(2), value;
      bool inline_value = false;
      if (const auto eq = name.find('='); eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        inline_value = true;
      }
      const Opt* o = findOpt(name);
      if (!o) throw InputError("unknown option --" + name + " (see --help)");
      if (o->is_flag) {
        if (inline_value) throw InputError("--" + name + " takes no value");
        flags_[name] = true;
      } else {
        if (!inline_value) {
          if (i + 1 >= args.size()) throw InputError("--" + name + " needs a value (" + o->metavar + ")");
          value = args[++i];
        }
        values_[name] = value;
      }
      continue;
    }
    positional.push_back(a);
  }
  size_t k = 0;
  for (const auto& p : pos_) {
    if (p.variadic) {
      while (k < positional.size()) pos_values_[p.name].push_back(positional[k++]);
      if (p.required && pos_values_[p.name].empty()) throw InputError("missing " + p.name + " (see --help)");
      break;
    }
    if (k < positional.size())
      pos_values_[p.name].push_back(positional[k++]);
    else if (p.required)
      throw InputError("missing " + p.name + " (see --help)");
  }
  if (k < positional.size()) throw InputError("unexpected argument '" + positional[k] + "' (see --help)");
  return true;
}

bool ArgParser::flag(const std::string& name) const {
  const auto it = flags_.find(name);
  return it != flags_.end() && it->second;
}

bool ArgParser::has(const std::string& name) const { return values_.count(name) > 0; }

std::string ArgParser::option(const std::string& name) const {
  const auto it = values_.find(name);
  if (it != values_.end()) return it->second;
  const Opt* o = findOpt(name);
  return o ? o->def : std::string();
}

double ArgParser::optionDouble(const std::string& name) const {
  const std::string s = option(name);
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v))
    throw InputError("--" + name + ": '" + s + "' is not a number");
  return v;
}

long ArgParser::optionInt(const std::string& name) const {
  const std::string s = option(name);
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE) throw InputError("--" + name + ": '" + s + "' is not a whole number");
  return v;
}

std::string ArgParser::positional(const std::string& name) const {
  const auto it = pos_values_.find(name);
  return it == pos_values_.end() || it->second.empty() ? std::string() : it->second.front();
}

std::vector<std::string> ArgParser::positionals(const std::string& name) const {
  const auto it = pos_values_.find(name);
  return it == pos_values_.end() ? std::vector<std::string>{} : it->second;
}

std::string ArgParser::helpText() const {
  std::ostringstream os;
  os << "usage: " << usage_ << "\n\n" << summary_ << "\n";
  if (!pos_.empty()) {
    os << "\narguments:\n";
    for (const auto& p : pos_) {
      std::string n = "  " + p.name + (p.variadic ? "..." : "");
      if (n.size() < 26) n.append(26 - n.size(), ' ');
      os << n << p.help << (p.required ? "" : " (optional)") << "\n";
    }
  }
  os << "\noptions:\n";
  std::vector<Opt> all = opts_;
  all.push_back({"help", "", "show this help and exit", "", true});
  for (const auto& o : all) {
    std::string n = "  --" + o.name + (o.is_flag ? "" : " " + o.metavar);
    if (n.size() < 26)
      n.append(26 - n.size(), ' ');
    else
      n += "  ";
    os << n << o.help;
    if (!o.is_flag && !o.def.empty()) os << " (default: " << o.def << ")";
    os << "\n";
  }
  if (!epilog_.empty()) os << "\n" << epilog_ << "\n";
  return os.str();
}

}  // namespace urbanslam::cli
