#include "urbanslam/io/MemorySource.h"

namespace urbanslam::io {

bool MemorySource::next(Measurement& out) {
  if (i_ >= m_.size()) return false;
  out = m_[i_++];
  return true;
}

double MemorySource::progress() const { return m_.empty() ? 1.0 : static_cast<double>(i_) / static_cast<double>(m_.size()); }

}  // namespace urbanslam::io
