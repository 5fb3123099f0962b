// The map file itself: a map read back writes the same bytes, and a file that is not a sound map
// of this version is refused with one error naming it.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <vector>

#include "MapFileSections.h"
#include "TestPaths.h"
#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/MotionIntegrator.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

slam::PipelineOptions fr079Options() { return slam::loadPipelineOptions(test::repoPath("ini/fr079.ini")); }

// A map part way through the Freiburg 079 excerpt (closures made, some awaiting confirmation).
std::string partialMapBytes() {
  slam::Pipeline p(fr079Options());
  auto src = io::openDataSource(test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz"));
  for (int i = 0; i < 1500; ++i) p.step(*src);
  return slam::encodeMap(p);
}

const std::string& mapBytes() {
  static const std::string bytes = partialMapBytes();
  return bytes;
}

std::string writeBytes(const std::string& name, const std::string& bytes) {
  const std::string path = (test::scratchDir("map_file_" + name) / "map.usmap").string();
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The error loadMap gives for `bytes` ("" when it loads).
std::string loadError(const std::string& name, const std::string& bytes, const slam::PipelineOptions* options = nullptr) {
  const std::string path = writeBytes(name, bytes);
  try {
    slam::loadMap(path, options);
  } catch (const common::InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;  // names the file first
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    return what;
  }
  return "";
}

constexpr size_t kHeaderBytes = 28;

}  // namespace

TEST(MapFile, SaveLoadSaveGivesTheSameBytes) {
  const std::string path = writeBytes("round_trip", mapBytes());
  const auto loaded = slam::loadMap(path);
  EXPECT_EQ(loaded->stats().measurements, 1500u);
  EXPECT_GT(loaded->loopClosures().size(), 0u);
  const std::string again = slam::encodeMap(*loaded);
  ASSERT_EQ(again.size(), mapBytes().size());
  EXPECT_TRUE(again == mapBytes());
  // saveMap writes exactly encodeMap's bytes.
  const std::string saved = (test::scratchDir("map_file_saved") / "again.usmap").string();
  slam::saveMap(*loaded, saved);
  EXPECT_TRUE(readBytes(saved) == mapBytes());
}

TEST(MapFile, HeaderIsLittleEndianWithTheFormatVersion) {
  const std::string& b = mapBytes();
  ASSERT_GT(b.size(), kHeaderBytes);
  EXPECT_EQ(b.substr(0, 5), "USMAP");
  EXPECT_EQ(static_cast<unsigned char>(b[8]), slam::kMapFormatVersion);
  EXPECT_EQ(b[9] | b[10] | b[11], 0);
  uint64_t length = 0, checksum = 0;
  for (int i = 7; i >= 0; --i) {
    length = length << 8 | static_cast<unsigned char>(b[12 + static_cast<size_t>(i)]);
    checksum = checksum << 8 | static_cast<unsigned char>(b[20 + static_cast<size_t>(i)]);
  }
  EXPECT_EQ(length, b.size() - kHeaderBytes);
  EXPECT_EQ(checksum, common::fnv1a64(b.data() + kHeaderBytes, b.size() - kHeaderBytes));
  EXPECT_EQ(b.substr(kHeaderBytes, 4), "OPTS");  // the options section comes first
}

TEST(MapFile, TruncatedFileIsRefused) {
  EXPECT_NE(loadError("truncated", mapBytes().substr(0, mapBytes().size() / 2)).find("truncated map"), std::string::npos);
  EXPECT_NE(loadError("truncated_header", mapBytes().substr(0, 15)).find("truncated map"), std::string::npos);
  EXPECT_NE(loadError("empty", "").find("not an urbanslam map"), std::string::npos);
}

TEST(MapFile, FlippedByteFailsTheChecksum) {
  std::string b = mapBytes();
  b[b.size() / 2] = static_cast<char>(b[b.size() / 2] ^ 0x10);
  EXPECT_NE(loadError("flipped", b).find("checksum"), std::string::npos);
}

TEST(MapFile, OtherVersionIsRefused) {
  std::string b = mapBytes();
  b[8] = static_cast<char>(slam::kMapFormatVersion + 1);
  const std::string e = loadError("version", b);
  EXPECT_NE(e.find("format version " + std::to_string(slam::kMapFormatVersion + 1)), std::string::npos) << e;
}

TEST(MapFile, OtherFilesAreNotMaps) {
  std::string b = mapBytes();
  b[0] = 'X';
  EXPECT_NE(loadError("magic", b).find("not an urbanslam map"), std::string::npos);
  EXPECT_NE(loadError("text", "# CARMEN Logfile\nODOM 0 0 0\n").find("not an urbanslam map"), std::string::npos);
}

// A payload with a valid checksum but a count far beyond the bytes left: refused before any
// allocation of that size.
TEST(MapFile, ImpossibleCountUnderAValidChecksumIsRefused) {
  std::string b = mapBytes();
  // The options text's length, right after the OPTS tag and its section length.
  const size_t at = kHeaderBytes + 4 + 8;
  for (size_t i = 0; i < 8; ++i) b[at + i] = static_cast<char>(0x7f);
  const uint64_t sum = common::fnv1a64(b.data() + kHeaderBytes, b.size() - kHeaderBytes);
  for (size_t i = 0; i < 8; ++i) b[20 + i] = static_cast<char>(static_cast<uint8_t>(sum >> (8 * i)));
  EXPECT_NE(loadError("count", b).find("corrupt map"), std::string::npos);
}

TEST(MapFile, ResumeRefusesChangedAlgorithmOptionsNamingTheKey) {
  slam::PipelineOptions o = fr079Options();
  o.loop_closure.max_candidates += 1;
  const std::string e = loadError("options", mapBytes(), &o);
  EXPECT_NE(e.find("[loop_closure] max_candidates"), std::string::npos) << e;
  // Output keys may change.
  slam::PipelineOptions out = fr079Options();
  out.output.write_pcd = !out.output.write_pcd;
  out.map.grid_resolution_m = 0.1;
  EXPECT_EQ(loadError("output_options", mapBytes(), &out), "");
}

TEST(MapFile, RunFolderNamesItsMap) {
  const auto dir = test::scratchDir("map_file_folder");
  EXPECT_THROW(slam::mapFilePath(dir.string()), common::InputError);
  std::ofstream((dir / "map.usmap").string(), std::ios::binary) << mapBytes();
  EXPECT_EQ(slam::mapFilePath(dir.string()), (dir / "map.usmap").string());
  EXPECT_EQ(slam::mapFilePath("x.usmap"), "x.usmap");
}

TEST(MapFile, FinishedRunCannotBeSaved) {
  slam::Pipeline p(fr079Options());
  auto src = io::openDataSource(test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz"));
  for (int i = 0; i < 200; ++i) p.step(*src);
  p.finish();
  EXPECT_THROW(slam::encodeMap(p), std::logic_error);
}

// The Tree of Words database is not in the file: a map that has one is refused on loading, with
// the reason, rather than continued without the images seen so far; localization, which only
// reads the keyframes' words, loads it.
TEST(MapFile, MapWithAnImageDatabaseIsRefusedUnlessOnlyRead) {
  slam::PipelineOptions o;
  o.loop_closure.image_detector = slam::LoopClosureOptions::ImageDetector::TreeOfWords;
  o.image_loop.vocabulary = test::repoPath("share/vision_loop/sift_k10_L4.usvoc");
  slam::Pipeline p(o);
  auto src = io::openDataSource(test::repoPath("rawlogs/rtabmap-loop-excerpt"));
  for (int i = 0; i < 4; ++i) p.step(*src);
  p.waitForGlobalSlam(*src);
  ASSERT_GT(p.keyframes().size(), 0u);
  const std::string bytes = slam::encodeMap(p);
  const std::string e = loadError("images", bytes);
  EXPECT_NE(e.find("image_detector = tree_of_words"), std::string::npos) << e;
  // Only read (localization), it loads: the keyframes with their images' words, as the run had them.
  const auto read = slam::loadMap(writeBytes("images_read", bytes), nullptr, nullptr, slam::MapUse::Localize);
  ASSERT_EQ(read->keyframes().size(), p.keyframes().size());
  size_t with_words = 0;
  for (size_t k = 0; k < p.keyframes().size(); ++k) {
    const auto &a = p.keyframes()[k].image_words.entries, &b = read->keyframes()[k].image_words.entries;
    with_words += !a.empty();
    ASSERT_EQ(a.size(), b.size()) << k;
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].word, b[i].word);
      EXPECT_EQ(a[i].weight, b[i].weight);
    }
  }
  EXPECT_GT(with_words, 0u);
}

// A file of the format before separate maps (version 3, written by that version: the fuzzing
// seed) is read as a map without any; written again, every section is as it was (the options
// aside: they list the keys added since), local SLAM's but for its heading corrections and its
// odometry outvotes (none learnt: five zeros), the statistics but for their durations
// (histograms now, one per step read), and the empty separate-maps section follows.
TEST(MapFile, AVersion3FileIsReadAsAMapWithoutSeparateMaps) {
  const std::string path = test::repoPath("fuzz/corpus/map_file/three-scans-24-beams.usmap");
  const std::string old = readBytes(path);
  ASSERT_EQ(old[8], 3);
  std::vector<std::unique_ptr<slam::Pipeline>> separate(1);
  const auto loaded = slam::loadMap(path, nullptr, &separate);
  EXPECT_TRUE(separate.empty());
  EXPECT_GT(loaded->keyframes().size(), 0u);
  const std::string now = slam::encodeMap(*loaded);
  EXPECT_EQ(now[8], static_cast<char>(slam::kMapFormatVersion));
  const auto a = test::mapFileSections(old), b = test::mapFileSections(now);
  EXPECT_EQ(a.size(), 7u);
  for (const char* tag : {"MAP ", "IMGS"}) {
    ASSERT_TRUE(a.count(tag) && b.count(tag)) << tag;
    EXPECT_TRUE(a.at(tag) == b.at(tag)) << "section " << tag << " differs";
  }
  // Global SLAM's section as it was, then the loop search's cursor: a map saved by a build
  // that searched each keyframe's closures when it was added has every keyframe searched and
  // none waiting.
  ASSERT_TRUE(a.count("GLOB") && b.count("GLOB"));
  const std::string& glob_old = a.at("GLOB");
  const std::string& glob_now = b.at("GLOB");
  ASSERT_GT(glob_now.size(), glob_old.size());
  EXPECT_TRUE(glob_now.compare(0, glob_old.size(), glob_old) == 0);
  const std::string cursor = glob_now.substr(glob_old.size());
  common::BinaryReader r(cursor.data(), cursor.size(), "cursor");
  const size_t n = loaded->keyframes().size();
  ASSERT_GT(n, 0u);
  EXPECT_EQ(r.size(), n);
  EXPECT_EQ(r.size(), 0u);
  // The filter as it was, with its chain's lineages (each pose's root and lineage, 8 bytes) and
  // then no record of factors since its factorisation (a count of 0 and false: it refactorises at
  // its next exact covariance) and the keyframe nodes of a reduced pose graph (the default) with
  // every keyframe its own filter pose: each keyframe's pose and false, no tail, no closure
  // through an offset.
  ASSERT_TRUE(a.count("ESDF") && b.count("ESDF"));
  common::BinaryWriter nodes;
  nodes.boolean(true);
  nodes.size(loaded->keyframes().size());
  for (size_t k = 0; k < loaded->keyframes().size(); ++k) {
    nodes.i32(static_cast<std::int32_t>(k));
    nodes.boolean(false);
  }
  nodes.size(0);
  nodes.size(loaded->keyframes().size());
  for (size_t k = 0; k < loaded->keyframes().size(); ++k) nodes.u8(0);
  const std::string& filter_old = a.at("ESDF") + std::string(9, '\0') + nodes.bytes();
  const std::string& filter_now = b.at("ESDF");
  ASSERT_GE(filter_now.size(), filter_old.size());
  const size_t lineages = filter_now.size() - filter_old.size();
  EXPECT_EQ(lineages % 8, 0u);
  bool as_it_was = lineages == 0 && filter_now == filter_old;
  for (size_t i = 0; i + lineages <= filter_now.size() && !as_it_was && lineages > 0; ++i)
    as_it_was = filter_now.substr(0, i) + filter_now.substr(i + lineages) == filter_old;
  EXPECT_TRUE(as_it_was) << "section ESDF differs beyond the chain's lineages, the factors since the factorisation and the keyframe nodes";
  ASSERT_TRUE(a.count("LOCL") && b.count("LOCL"));
  // Version 13 follows each point of the submap's point sets (after the motion integrator's
  // state: libs/slam/README.md, LOCL) with the position of the sensor that saw it, which a
  // version 3 file has not: read as the set's origin, written as zeros.
  const std::string& local_v3 = a.at("LOCL");
  std::string local_old;
  {
    common::BinaryReader r(local_v3.data(), local_v3.size(), "LOCL");
    size_t copied = 0;  // local_v3's bytes up to where r has read, copied into local_old
    const auto copy = [&] {
      const size_t at = local_v3.size() - r.remaining();
      local_old += local_v3.substr(copied, at - copied);
      copied = at;
    };
    slam::MotionIntegrator(slam::MotionOptions{}, slam::VehicleOptions{}).readState(r);
    std::string point((2 + 4 + 2) * 8 + 4, '\0');  // position, covariance, range, bearing, beam
    for (size_t set = 0, sets = r.size(); set < sets; ++set) {
      for (size_t p = 0, points = r.size(); p < points; ++p) {
        r.raw(point.data(), point.size());
        copy();
        local_old += std::string(16, '\0');
      }
    }
    local_old += local_v3.substr(copied);
  }
  const std::string& local_now = b.at("LOCL");
  // The heading corrections (three f64) and the odometry outvotes (two f64) follow each other.
  const size_t learnt = 24 + 16;
  ASSERT_EQ(local_now.size(), local_old.size() + learnt);
  bool inserted = false;  // that many zero bytes somewhere, the rest as it was
  for (size_t i = 0; i + learnt <= local_now.size() && !inserted; ++i)
    inserted =
        local_now.compare(i, learnt, std::string(learnt, '\0')) == 0 && local_now.substr(0, i) + local_now.substr(i + learnt) == local_old;
  EXPECT_TRUE(inserted) << "section LOCL differs beyond the heading corrections, the odometry outvotes and the sensor positions";
  ASSERT_TRUE(b.count("SEPM"));
  EXPECT_EQ(b.at("SEPM"), std::string(8, '\0'));  // a count of 0
  // The durations read into histograms: one per step, and they stay as they are once written so.
  const slam::PipelineStats& st = loaded->stats();
  EXPECT_GT(st.step_ms.count(), 0u);
  size_t by_decade = 0;
  for (const auto& d : st.step_ms_by_decade) by_decade += d.count();
  EXPECT_EQ(by_decade, st.step_ms.count());
  const std::string again_path = testing::TempDir() + "version3-written-again.usmap";
  {
    std::ofstream f(again_path, std::ios::binary);
    f << now;
  }
  const auto again = slam::loadMap(again_path);
  EXPECT_EQ(again->stats().step_ms.count(), st.step_ms.count());
  EXPECT_EQ(again->stats().step_ms.max(), st.step_ms.max());
  EXPECT_TRUE(test::mapFileSections(slam::encodeMap(*again)).at("STAT") == b.at("STAT"));
  std::remove(again_path.c_str());
}
