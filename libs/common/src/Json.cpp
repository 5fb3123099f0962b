#include "urbanslam/common/Json.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace urbanslam::common {

Json& Json::operator[](const std::string& key) {
  if (type_ == Type::Null) type_ = Type::Object;
  if (type_ != Type::Object) throw std::logic_error("Json: operator[] on a non-object");
  for (size_t i = 0; i < keys_.size(); ++i)
    if (keys_[i] == key) return items_[i];
  keys_.push_back(key);
  items_.emplace_back();
  return items_.back();
}

Json& Json::push(Json v) {
  if (type_ == Type::Null) type_ = Type::Array;
  if (type_ != Type::Array) throw std::logic_error("Json: push on a non-array");
  items_.push_back(std::move(v));
  return items_.back();
}

bool Json::contains(const std::string& key) const {
  for (const auto& k : keys_)
    if (k == key) return true;
  return false;
}

const Json& Json::at(const std::string& key) const {
  for (size_t i = 0; i < keys_.size(); ++i)
    if (keys_[i] == key) return items_[i];
  throw std::out_of_range("Json: no key '" + key + "'");
}

double Json::asNumber() const {
  if (type_ == Type::Integer) return static_cast<double>(integer_);
  if (type_ == Type::Number) return number_;
  throw std::logic_error("Json: not a number");
}

std::string jsonEscape(const std::string& s) {
  std::string out;
  out.reserve(s.size() + 2);
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out;
}

std::string Json::dump(int indent) const {
  std::string out;
  dumpTo(out, indent, 0);
  return out;
}

void Json::dumpTo(std::string& out, int indent, int depth) const {
  const auto newline = [&](int d) {
    if (indent < 0) return;
    out += '\n';
    out.append(static_cast<size_t>(indent * d), ' ');
  };
  switch (type_) {
    case Type::Null:
      out += "null";
      break;
    case Type::Bool:
      out += bool_ ? "true" : "false";
      break;
    case Type::Integer:
      out += std::to_string(integer_);
      break;
    case Type::Number: {
      if (!std::isfinite(number_)) {
        out += "null";
        break;
      }
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.15g", number_);
      out += buf;
      break;
    }
    case Type::String:
      out += '"' + jsonEscape(string_) + '"';
      break;
    case Type::Array:
    case Type::Object: {
      const bool obj = type_ == Type::Object;
      out += obj ? '{' : '[';
      for (size_t i = 0; i < items_.size(); ++i) {
        if (i) out += ',';
        newline(depth + 1);
        if (obj) out += '"' + jsonEscape(keys_[i]) + (indent < 0 ? "\":" : "\": ");
        items_[i].dumpTo(out, indent, depth + 1);
      }
      if (!items_.empty()) newline(depth);
      out += obj ? '}' : ']';
      break;
    }
  }
}

}  // namespace urbanslam::common
