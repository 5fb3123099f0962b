#pragma once
// A watch on the bytes MRPT reads for a CActionRobotMovement2D, refusing the fields that would
// crash MRPT's own reader (used by the rawlog reader's stream; internal to libs/io).
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace urbanslam::io::detail {

// MRPT dereferences the pose change of a CActionRobotMovement2D without checking it: unless the
// estimation method is odometry (0), the object read next must be a pose PDF, and when it is of
// another class or a null object, MRPT segfaults while it reads. There is no size prefix to look
// ahead with, so the stream checks those fields as MRPT reads them (each field is one Read): the
// object's header, the estimation method (0 or 1), and the class of the pose PDF that follows.
class MovementGuard {
 public:
  // Throws std::runtime_error on a field that would crash MRPT; MRPT wraps it in its own
  // exception, so the cause is also kept for the error message.
  const std::string& failure() const { return failure_; }
  void check(const unsigned char* data, size_t n) {
    switch (state_) {
      case State::Idle:
        break;
      case State::Method: {
        state_ = State::Idle;
        if (n != 4) break;
        uint32_t method = 0;
        for (int b = 3; b >= 0; --b) method = method << 8 | data[b];
        if (method == 1) state_ = State::PdfHeader;
        if (method > 1) fail("unknown estimation method " + std::to_string(method) + " (0 odometry, 1 scan matching)");
        return;
      }
      case State::PdfHeader:
        state_ = State::Idle;
        if (n != 1) break;
        if (data[0] & 0x80) {
          name_length_ = data[0] & 0x7f;
          state_ = State::PdfName;
        } else {  // the old header: a 4-byte name length
          name_length_ = data[0];
          state_ = State::PdfOldLength;
        }
        return;
      case State::PdfOldLength:
        state_ = State::Idle;
        if (n != 3) break;
        name_length_ |= size_t{data[0]} << 8 | size_t{data[1]} << 16 | size_t{data[2]} << 24;
        state_ = State::PdfName;
        return;
      case State::PdfName: {
        state_ = State::Idle;
        const std::string name(reinterpret_cast<const char*>(data), n);
        if (n != name_length_ || !(name.rfind("CPosePDF", 0) == 0 || name.rfind("mrpt::poses::CPosePDF", 0) == 0))
          fail("its pose change is a " + printable(name) + ", not a pose PDF");
        return;
      }
    }
    // The object's header: its name (one Read), then its version (one byte).
    if (n == 1 && (tail_ == kName || tail_ == kFullName)) {
      const unsigned version = data[0];
      state_ = version <= 1 ? State::PdfHeader : version <= 7 ? State::Method : State::Idle;
    }
    tail_.assign(reinterpret_cast<const char*>(data), std::min<size_t>(n, 64));
  }

 private:
  enum class State { Idle, Method, PdfHeader, PdfOldLength, PdfName };
  [[noreturn]] void fail(const std::string& why) {
    failure_ = "CActionRobotMovement2D: " + why;
    throw std::runtime_error(failure_);
  }
  static std::string printable(std::string s) {
    if (s.size() > 40) s = s.substr(0, 40) + "...";
    for (char& c : s)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != ':' && c != '_') c = '?';
    return s;
  }
  static inline const std::string kName = "CActionRobotMovement2D";
  static inline const std::string kFullName = "mrpt::obs::CActionRobotMovement2D";
  State state_ = State::Idle;
  size_t name_length_ = 0;
  std::string tail_;  // the previous Read
  std::string failure_;
};

}  // namespace urbanslam::io::detail
