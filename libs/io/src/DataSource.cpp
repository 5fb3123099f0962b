#include "urbanslam/io/DataSource.h"

#include <filesystem>

#include "TextScanner.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/CarmenReader.h"
#include "urbanslam/io/GfsReader.h"
#include "urbanslam/io/ImageFolderSource.h"
#include "urbanslam/io/RawlogReader.h"
#include "urbanslam/io/VictoriaParkReader.h"

namespace urbanslam::io {

namespace fs = std::filesystem;
using common::InputError;

LogFormat detectLogFormat(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path + ": no such file or folder");
  if (VictoriaParkReader::looksLike(path)) return LogFormat::VictoriaPark;
  if (fs::is_directory(path, ec)) return ImageFolderSource::looksLike(path) ? LogFormat::ImageFolder : LogFormat::Unknown;
  // Look at the (decompressed) head: CARMEN logs are text with known message tags; anything
  // else binary is tried as an MRPT rawlog (whose reader reports a clear error if it is not).
  auto in = detail::openGzFile(path);
  std::string head(4096, '\0');
  size_t got = 0;
  try {
    got = in->read(head.data(), head.size());
  } catch (const InputError&) {
    got = 0;  // a truncated gzip too short to read its head: let the rawlog reader say so
  }
  head.resize(got);
  if (got == 0) throw InputError(path + ": empty file");
  if (GfsReader::sniff(head)) return LogFormat::Gfs;  // before CARMEN: gfs logs also have PARAM/ODOM
  if (CarmenReader::sniff(head)) return LogFormat::Carmen;
  size_t printable = 0;
  for (unsigned char c : head) printable += (c >= 32 && c < 127) || c == '\n' || c == '\r' || c == '\t';
  if (printable == head.size()) return LogFormat::Unknown;  // text, but not CARMEN
  return LogFormat::MrptRawlog;
}

std::unique_ptr<DataSource> openDataSource(const std::string& path) {
  switch (detectLogFormat(path)) {
    case LogFormat::MrptRawlog:
      return std::make_unique<RawlogReader>(path);
    case LogFormat::Carmen:
      return std::make_unique<CarmenReader>(path);
    case LogFormat::Gfs:
      return std::make_unique<GfsReader>(path);
    case LogFormat::VictoriaPark:
      return std::make_unique<VictoriaParkReader>(path);
    case LogFormat::ImageFolder:
      return std::make_unique<ImageFolderSource>(path);
    case LogFormat::Unknown:
      break;
  }
  throw InputError(path +
                   ": unrecognised format (expected an MRPT rawlog, a CARMEN log, a GMapping gfs log, a Victoria Park folder/zip or a "
                   "folder of images)");
}

}  // namespace urbanslam::io
