#include "urbanslam/slam/MapFile.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/OptionsSchema.h"

namespace urbanslam::slam {

namespace {

// "USMAP", then CR LF and Ctrl-Z as PNG does: a transfer that translates line ends or a reader
// that stops at end-of-file characters breaks the signature rather than the payload.
constexpr char kMagic[8] = {'U', 'S', 'M', 'A', 'P', '\r', '\n', '\x1a'};
constexpr size_t kHeaderBytes = 8 + 4 + 8 + 8;  // magic, version, payload length, checksum
constexpr std::uint32_t kOptionsTag = common::sectionTag("OPTS");

// Sections whose keys only change what is written, not what is computed.
bool outputOnly(const std::string& section) { return section == "map" || section == "output"; }

void checkSameAlgorithmOptions(const PipelineOptions& saved, const PipelineOptions& requested, const std::string& path) {
  PipelineOptions a = saved, b = requested;  // the schemas bind to mutable members
  common::OptionsSchema sa, sb;
  declareOptions(sa, a);
  declareOptions(sb, b);
  for (size_t i = 0; i < sa.options().size(); ++i) {
    const auto& oa = sa.options()[i];
    const auto& ob = sb.options()[i];
    if (outputOnly(oa.section)) continue;
    const std::string va = oa.get(), vb = ob.get();
    if (va != vb)
      throw common::ConfigError(path + ": built with [" + oa.section + "] " + oa.key + " = " + va + ", where the options given say " + vb +
                                ": a resumed run keeps the options that change the result (only [map] and [output] may differ)");
  }
}

std::string readWholeFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw common::InputError(path + ": a folder, not a map file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw common::InputError(path + ": cannot open the map file");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw common::InputError(path + ": cannot read the map file");
  return bytes;
}

std::uint64_t readU64(const std::string& bytes, size_t at) {
  std::uint64_t v = 0;
  for (size_t i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[at + i])) << (8 * i);
  return v;
}

}  // namespace

std::string encodeMap(const Pipeline& pipeline) {
  common::BinaryWriter payload;
  payload.beginSection(kOptionsTag);
  payload.string(optionsToIni(pipeline.options()));
  payload.endSection();
  pipeline.writeState(payload);
  const std::string body = payload.take();

  common::BinaryWriter file;
  file.raw(kMagic, sizeof kMagic);
  file.u32(kMapFormatVersion);
  file.size(body.size());
  file.u64(common::fnv1a64(body.data(), body.size()));
  file.raw(body.data(), body.size());
  return file.take();
}

void writeMapFile(const std::string& bytes, const std::string& path) {
  common::AtomicFile f(path, true);
  f.stream().write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  f.commit();
}

std::string mapFilePath(const std::string& file_or_run_folder) {
  std::error_code ec;
  if (std::filesystem::is_directory(file_or_run_folder, ec)) {
    const std::string inside = (std::filesystem::path(file_or_run_folder) / kMapFileName).string();
    if (!std::filesystem::exists(inside, ec))
      throw common::InputError(file_or_run_folder + ": a folder without " + kMapFileName + " (not a run folder of this version?)");
    return inside;
  }
  return file_or_run_folder;
}

std::unique_ptr<Pipeline> loadMap(const std::string& path, const PipelineOptions* options) {
  const std::string bytes = readWholeFile(path);
  // The signature first: a file that is not a map is told so, even a short one.
  const size_t sig = std::min(bytes.size(), sizeof kMagic);
  if (bytes.empty() || std::memcmp(bytes.data(), kMagic, sig) != 0)
    throw common::InputError(path + ": not an urbanslam map (it does not start with the USMAP signature)");
  if (bytes.size() < kHeaderBytes)
    throw common::InputError(path + ": truncated map: " + std::to_string(bytes.size()) + " bytes, shorter than the header");
  common::BinaryReader header(bytes.data() + sizeof kMagic, kHeaderBytes - sizeof kMagic, path, "corrupt map");
  const std::uint32_t version = header.u32();
  if (version != kMapFormatVersion)
    throw common::InputError(path + ": map format version " + std::to_string(version) + ", but this urbanslam reads version " +
                             std::to_string(kMapFormatVersion) + " only");
  const std::uint64_t length = readU64(bytes, 12), checksum = readU64(bytes, 20);
  const size_t available = bytes.size() - kHeaderBytes;
  if (length > available)
    throw common::InputError(path + ": truncated map: " + std::to_string(available) + " of its " + std::to_string(length) +
                             " payload bytes");
  if (length < available)
    throw common::InputError(path + ": corrupt map: " + std::to_string(available - length) + " bytes after the payload");
  const char* payload = bytes.data() + kHeaderBytes;
  if (common::fnv1a64(payload, available) != checksum)
    throw common::InputError(path + ": corrupt map: the payload's checksum does not match (changed or damaged after it was written)");

  common::BinaryReader r(payload, available, path, "corrupt map");
  common::BinaryReader opts = r.section(kOptionsTag);
  const PipelineOptions saved = parsePipelineOptions(opts.string(), path + " (its saved options)");
  opts.expectEnd();
  if (options) checkSameAlgorithmOptions(saved, *options, path);
  auto pipeline = std::make_unique<Pipeline>(options ? *options : saved);
  pipeline->readState(r);
  return pipeline;
}

}  // namespace urbanslam::slam
