#pragma once
// Input files the command-line tests write: plain bytes, and gzip read and written with MRPT's
// streams (the rawlogs' own compression).
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>

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

// A CARMEN log (gzipped) split after its first `scans` laser scans into `dir`/first.clf and
// `dir`/rest.clf; both parts keep the header lines (the sensor's description).
inline std::pair<std::string, std::string> splitCarmenLog(const std::string& gz, const std::filesystem::path& dir, size_t scans) {
  std::istringstream in(gunzip(gz));
  std::string header, a, b, line;
  size_t seen = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("PARAM", 0) == 0) {
      header += line + "\n";
      continue;
    }
    if (line.rfind("FLASER", 0) == 0) ++seen;
    (seen <= scans ? a : b) += line + "\n";
  }
  return {writeFile(dir / "first.clf", header + a), writeFile(dir / "rest.clf", header + b)};
}

}  // namespace urbanslam::test
