#pragma once
// A log that starts after its first N measurements: what a second log starting where the first
// one ended looks like to the pipeline (the reader still reads the skipped part, so readers that
// carry state from one entry to the next, such as accumulated odometry, stay as they were).
#include <memory>

#include "urbanslam/io/DataSource.h"

namespace urbanslam::test {

class SkippingSource : public io::DataSource {
 public:
  SkippingSource(std::unique_ptr<io::DataSource> inner, size_t skip)
      : io::DataSource(inner->path()), inner_(std::move(inner)), skip_(skip) {}

  bool next(io::Measurement& out) override {
    for (; skip_ > 0; --skip_)
      if (!inner_->next(out)) return false;
    return inner_->next(out);
  }
  double progress() const override { return inner_->progress(); }
  std::string format() const override { return inner_->format(); }

 private:
  std::unique_ptr<io::DataSource> inner_;
  size_t skip_;
};

}  // namespace urbanslam::test
