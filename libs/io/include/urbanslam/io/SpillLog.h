#pragma once
// A sequence that only grows and is read back whole, in order, when the run writes its outputs
// or saves its map: every loop-closure hypothesis and its fate, every odometry reading. A city
// of a million keyframes has several million of them, and nothing during the run looks back
// further than the last few. The newest entries (between `chunk` and twice that) stay in
// memory, where the newest can still be amended; older ones are written, `chunk` at a time,
// to a scratch file (io::ScratchFile) and read back chunk by chunk when the sequence is walked.
//
// `Codec` turns an entry into bytes and back: static void write(common::BinaryWriter&,
// const T&) and static T read(common::BinaryReader&). Not thread-safe: one thread appends,
// and it or another reads when the appending is done.
#include <cstdint>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/io/ScratchFile.h"

namespace urbanslam::io {

template <class T, class Codec>
class SpillLog {
 public:
  // Entries written to the file at a time: a few hundred kilobytes of records, and as many
  // always in memory for amendNewest.
  static constexpr size_t kDefaultChunk = 4096;

  // `owner` names the scratch file in error messages; `dir` empty: the system's temporary
  // folder.
  explicit SpillLog(std::string owner, std::string dir = {}, size_t chunk = kDefaultChunk)
      : chunk_(chunk == 0 ? 1 : chunk), file_(std::move(owner), std::move(dir)) {}

  size_t size() const { return spilled_ + recent_.size(); }
  bool empty() const { return size() == 0; }

  void push_back(const T& v) {
    recent_.push_back(v);
    if (recent_.size() >= 2 * chunk_) spillOldest();
  }

  // Calls f(entry) on the entries still in memory, newest first, for as long as it returns
  // true: amends what was just added (at least the newest `chunk` are in memory).
  template <class F>
  void amendNewest(F f) {
    for (auto it = recent_.rbegin(); it != recent_.rend() && f(*it); ++it) {
    }
  }

  // Calls f(entry) on every entry, oldest first. Throws std::runtime_error when the scratch
  // file cannot be read back.
  template <class F>
  void forEach(F f) const {
    std::uint64_t offset = 0;
    for (const std::uint64_t end : chunk_ends_) {
      const std::string bytes = file_.read(offset, static_cast<size_t>(end - offset));
      common::BinaryReader r(bytes.data(), bytes.size(), "spill file");
      for (size_t i = 0; i < chunk_; ++i) f(static_cast<const T&>(Codec::read(r)));
      r.expectEnd();
      offset = end;
    }
    for (const T& v : recent_) f(v);
  }

  // Every entry in a vector (for small sequences and tests).
  std::vector<T> toVector() const {
    std::vector<T> out;
    out.reserve(size());
    forEach([&](const T& v) { out.push_back(v); });
    return out;
  }

  void clear() {
    recent_.clear();
    chunk_ends_.clear();
    spilled_ = 0;
    file_.clear();
  }

 private:
  void spillOldest() {
    common::BinaryWriter w;
    for (size_t i = 0; i < chunk_; ++i) Codec::write(w, recent_[i]);
    file_.append(w.bytes());
    chunk_ends_.push_back(file_.size());
    recent_.erase(recent_.begin(), recent_.begin() + static_cast<std::ptrdiff_t>(chunk_));
    spilled_ += chunk_;
  }

  size_t chunk_;
  std::deque<T> recent_;                   // entries [spilled_, size())
  size_t spilled_ = 0;                     // entries in the file: chunk_ends_.size() chunks
  std::vector<std::uint64_t> chunk_ends_;  // the file offset where each chunk ends
  ScratchFile file_;
};

}  // namespace urbanslam::io
