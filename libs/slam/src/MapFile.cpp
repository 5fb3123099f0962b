#include "urbanslam/slam/MapFile.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/MappedFile.h"
#include "urbanslam/common/OptionsSchema.h"

namespace urbanslam::slam {

namespace {

// "USMAP", then CR LF and Ctrl-Z as PNG does: a transfer that translates line ends or a reader
// that stops at end-of-file characters breaks the signature rather than the payload.
constexpr char kMagic[8] = {'U', 'S', 'M', 'A', 'P', '\r', '\n', '\x1a'};
constexpr size_t kHeaderBytes = 8 + 4 + 8 + 8;  // magic, version, payload length, checksum
constexpr size_t kLengthOffset = 8 + 4;         // where the payload length and checksum go
constexpr std::uint32_t kOptionsTag = common::sectionTag("OPTS");
constexpr std::uint32_t kSeparateTag = common::sectionTag("SEPM");

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

// The map file mapped into memory (its pages given back as they are read: MappedFile).
std::unique_ptr<common::MappedFile> mapWholeFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw common::InputError(path + ": a folder, not a map file");
  if (!std::filesystem::exists(path, ec)) throw common::InputError(path + ": cannot open the map file");
  return std::make_unique<common::MappedFile>(path);
}

std::uint64_t readU64(const char* bytes, size_t at) {
  std::uint64_t v = 0;
  for (size_t i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[at + i])) << (8 * i);
  return v;
}

}  // namespace

void writeMap(const Pipeline& pipeline, std::iostream& out, const std::string& name, const std::vector<const Pipeline*>& separate) {
  // The header with a zero length and checksum, the payload straight to the stream a megabyte at
  // a time, then the payload read back for its checksum and the header completed: no copy of
  // the map in memory, however large.
  common::BinaryWriter w(&out);
  w.raw(kMagic, sizeof kMagic);
  w.u32(kMapFormatVersion);
  w.size(0);
  w.u64(0);
  w.beginSection(kOptionsTag);
  w.string(optionsToIni(pipeline.options()));
  w.endSection();
  pipeline.writeState(w);
  w.beginSection(kSeparateTag);
  w.size(separate.size());
  for (const auto& p : separate) p->writeState(w);
  w.endSection();
  w.flush();
  const std::uint64_t length = w.position() - kHeaderBytes;
  out.flush();
  out.seekg(static_cast<std::streamoff>(kHeaderBytes));
  std::uint64_t sum = common::kFnv1a64Start;
  std::vector<char> chunk(1 << 20);
  for (std::uint64_t left = length; left > 0;) {
    const size_t n = static_cast<size_t>(std::min<std::uint64_t>(left, chunk.size()));
    if (!out.read(chunk.data(), static_cast<std::streamsize>(n)))
      throw common::InputError(name + ": cannot read back the map being written");
    sum = common::fnv1a64(chunk.data(), n, sum);
    left -= n;
  }
  common::BinaryWriter header;
  header.size(length);
  header.u64(sum);
  out.clear();
  out.seekp(static_cast<std::streamoff>(kLengthOffset));
  out.write(header.bytes().data(), static_cast<std::streamsize>(header.bytes().size()));
  out.flush();
  if (!out) throw common::InputError(name + ": cannot write the map file (disk full?)");
}

std::string encodeMap(const Pipeline& pipeline, const std::vector<const Pipeline*>& separate) {
  std::stringstream s(std::ios::in | std::ios::out | std::ios::binary);
  writeMap(pipeline, s, "map", separate);
  return s.str();
}

void writeMapFile(const Pipeline& pipeline, const std::string& path, const std::vector<const Pipeline*>& separate) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::trunc | std::ios::binary);
  if (!f) throw common::InputError(path + ": cannot create the map file (is its folder writable?)");
  writeMap(pipeline, f, path, separate);
  f.close();
  if (f.fail()) throw common::InputError(path + ": cannot write the map file (disk full?)");
}

void saveMap(const Pipeline& pipeline, const std::string& path, const std::vector<const Pipeline*>& separate) {
  common::writeAtomically(path, [&](const std::string& tmp) { writeMapFile(pipeline, tmp, separate); });
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

std::unique_ptr<Pipeline> loadMap(const std::string& path, const PipelineOptions* options,
                                  std::vector<std::unique_ptr<Pipeline>>* separate, MapUse use) {
  const std::unique_ptr<common::MappedFile> file = mapWholeFile(path);
  const char* bytes = file->data();
  const size_t size = file->size();
  // The signature first: a file that is not a map is told so, even a short one.
  const size_t sig = std::min(size, sizeof kMagic);
  if (size == 0 || std::memcmp(bytes, kMagic, sig) != 0)
    throw common::InputError(path + ": not an urbanslam map (it does not start with the USMAP signature)");
  if (size < kHeaderBytes) throw common::InputError(path + ": truncated map: " + std::to_string(size) + " bytes, shorter than the header");
  common::BinaryReader header(bytes + sizeof kMagic, kHeaderBytes - sizeof kMagic, path, "corrupt map");
  const std::uint32_t version = header.u32();
  if (version < kOldestMapFormatVersion || version > kMapFormatVersion)
    throw common::InputError(path + ": map format version " + std::to_string(version) + ", but this urbanslam reads versions " +
                             std::to_string(kOldestMapFormatVersion) + " to " + std::to_string(kMapFormatVersion) + " only");
  const std::uint64_t length = readU64(bytes, kLengthOffset), checksum = readU64(bytes, kLengthOffset + 8);
  const size_t available = size - kHeaderBytes;
  if (length > available)
    throw common::InputError(path + ": truncated map: " + std::to_string(available) + " of its " + std::to_string(length) +
                             " payload bytes");
  if (length < available)
    throw common::InputError(path + ": corrupt map: " + std::to_string(available - length) + " bytes after the payload");
  const char* payload = bytes + kHeaderBytes;
  // The checksum a stretch at a time, each stretch's pages given back after it.
  std::uint64_t h = common::kFnv1a64Start;
  for (size_t at = 0; at < available; at += file->stretchBytes()) {
    const size_t n = std::min(file->stretchBytes(), available - at);
    h = common::fnv1a64(payload + at, n, h);
    file->release(payload + at, payload + at + n);
  }
  if (h != checksum)
    throw common::InputError(path + ": corrupt map: the payload's checksum does not match (changed or damaged after it was written)");

  common::BinaryReader r(payload, available, path, "corrupt map", file.get());
  common::BinaryReader opts = r.section(kOptionsTag);
  const PipelineOptions saved = parsePipelineOptions(opts.string(), path + " (its saved options)");
  opts.expectEnd();
  if (options) checkSameAlgorithmOptions(saved, *options, path);
  const PipelineOptions& used = options ? *options : saved;
  auto pipeline = std::make_unique<Pipeline>(used);
  const bool continued = use == MapUse::Continue;
  pipeline->readState(r, version, continued);
  if (separate) separate->clear();
  if (version >= 4) {
    common::BinaryReader maps = r.section(kSeparateTag);
    if (separate) {
      const size_t n = maps.count(6 * 12);  // a map is at least its six sections' tags and lengths
      for (size_t i = 0; i < n; ++i) {
        separate->push_back(std::make_unique<Pipeline>(used));
        separate->back()->readState(maps, version, continued);
      }
      maps.expectEnd();
    }
  }
  r.expectEnd();
  return pipeline;
}

}  // namespace urbanslam::slam
