#pragma once
// Command-line parsing for the subcommands: GNU-style `--name value` / `--name=value` options,
// flags, positionals, and a generated --help. Bad arguments throw common::InputError (exit 2).
#include <map>
#include <string>
#include <vector>

namespace urbanslam::cli {

class ArgParser {
 public:
  // usage: e.g. "urbanslam graph IN [--out OUT.g2o] [--json]".
  ArgParser(std::string usage, std::string summary);

  void addFlag(const std::string& name, const std::string& help);
  void addOption(const std::string& name, const std::string& metavar, const std::string& help, const std::string& default_value = "");
  // A trailing positional may be variadic (collects the rest); required positionals come first.
  void addPositional(const std::string& name, const std::string& help, bool required = true, bool variadic = false);
  // Free text appended to --help (examples, output description).
  void addEpilog(const std::string& text) { epilog_ = text; }

  // Returns false when --help/-h was given (help already printed to stdout; exit 0).
  bool parse(const std::vector<std::string>& args);

  bool flag(const std::string& name) const;
  // Value of an option (its default when not given); has() tells whether it was given.
  std::string option(const std::string& name) const;
  bool has(const std::string& name) const;
  double optionDouble(const std::string& name) const;
  long optionInt(const std::string& name) const;
  // A single positional ("" when optional and absent), or all values of a variadic one.
  std::string positional(const std::string& name) const;
  std::vector<std::string> positionals(const std::string& name) const;

  std::string helpText() const;

 private:
  struct Opt {
    std::string name, metavar, help, def;
    bool is_flag = false;
  };
  struct Pos {
    std::string name, help;
    bool required = true, variadic = false;
  };
  const Opt* findOpt(const std::string& name) const;

  std::string usage_, summary_, epilog_;
  std::vector<Opt> opts_;
  std::vector<Pos> pos_;
  std::map<std::string, std::string> values_;
  std::map<std::string, bool> flags_;
  std::map<std::string, std::vector<std::string>> pos_values_;
};

}  // namespace urbanslam::cli
