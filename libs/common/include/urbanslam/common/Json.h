#pragma once
// A small ordered JSON value for `--json` outputs and stats.json (writing only: nothing in the
// project parses JSON). Keys keep their insertion order so outputs diff cleanly.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace urbanslam::common {

class Json {
 public:
  enum class Type { Null, Bool, Number, Integer, String, Array, Object };

  Json() = default;
  Json(bool b) : type_(Type::Bool), bool_(b) {}                                              // NOLINT
  Json(double d) : type_(Type::Number), number_(d) {}                                        // NOLINT
  Json(int i) : type_(Type::Integer), integer_(i) {}                                         // NOLINT
  Json(long i) : type_(Type::Integer), integer_(i) {}                                        // NOLINT
  Json(long long i) : type_(Type::Integer), integer_(i) {}                                   // NOLINT
  Json(unsigned long i) : type_(Type::Integer), integer_(static_cast<long long>(i)) {}       // NOLINT
  Json(unsigned long long i) : type_(Type::Integer), integer_(static_cast<long long>(i)) {}  // NOLINT
  Json(unsigned i) : type_(Type::Integer), integer_(i) {}                                    // NOLINT
  Json(const char* s) : type_(Type::String), string_(s) {}                                   // NOLINT
  Json(std::string s) : type_(Type::String), string_(std::move(s)) {}                        // NOLINT

  static Json array() {
    Json j;
    j.type_ = Type::Array;
    return j;
  }
  static Json object() {
    Json j;
    j.type_ = Type::Object;
    return j;
  }
  template <typename T>
  static Json arrayOf(const std::vector<T>& v) {
    Json j = array();
    for (const auto& x : v) j.push(Json(x));
    return j;
  }

  // Object access: inserts the key (in order) when absent. A reference it returns is valid only
  // until the next key is inserted into the same object (the values live in a vector).
  Json& operator[](const std::string& key);
  Json& push(Json v);
  Type type() const { return type_; }
  bool contains(const std::string& key) const;
  const Json& at(const std::string& key) const;
  double asNumber() const;
  const std::string& asString() const { return string_; }
  size_t size() const { return type_ == Type::Array ? items_.size() : keys_.size(); }

  // Compact (indent < 0) or pretty-printed text. Non-finite numbers become null.
  std::string dump(int indent = -1) const;

 private:
  void dumpTo(std::string& out, int indent, int depth) const;

  Type type_ = Type::Null;
  bool bool_ = false;
  double number_ = 0;
  long long integer_ = 0;
  std::string string_;
  std::vector<Json> items_;  // array items, or object values (parallel to keys_)
  std::vector<std::string> keys_;
};

std::string jsonEscape(const std::string& s);

}  // namespace urbanslam::common
