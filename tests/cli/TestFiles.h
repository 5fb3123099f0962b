#pragma once
// Input files the command-line tests write: plain bytes, and gzip read and written with MRPT's
// streams (the rawlogs' own compression).
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace urbanslam::test {

inline std::string writeFile(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
  return p.string();
}

inline std::string gunzip(const std::string& path) {
  mrpt::io::CFileGZInputStream in(path);
  std::string out;
  char buf[1 << 16];
  for (size_t n; (n = in.Read(buf, sizeof buf)) > 0;) out.append(buf, n);
  return out;
}

inline std::string writeGz(const std::filesystem::path& p, const std::string& bytes) {
  mrpt::io::CFileGZOutputStream out(p.string());
  out.Write(bytes.data(), bytes.size());
  return p.string();
}

}  // namespace urbanslam::test
