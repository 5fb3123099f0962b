#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <random>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/vision_loop/VocabularyFile.h"
#include "urbanslam/vision_loop/VocabularyTrainer.h"

using namespace urbanslam::vision_loop;
using urbanslam::common::InputError;

namespace {

Vocabulary randomVocabulary(DescriptorType type) {
  std::mt19937_64 rng(9);
  std::vector<cv::Mat> images;
  for (int i = 0; i < 20; ++i) {
    cv::Mat d(50, descriptorBytes(type), CV_8U);
    for (int r = 0; r < d.rows; ++r)
      for (int c = 0; c < d.cols; ++c) d.at<uint8_t>(r, c) = static_cast<uint8_t>(rng() % (type == DescriptorType::Sift ? 60 : 256));
    images.push_back(d);
  }
  KMeansOptions o;
  o.branching = 4;
  o.depth = 3;
  o.threads = 2;
  return trainVocabulary(images, type, o);
}

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void writeAll(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

void expectRefused(const std::string& path, const std::string& fragment) {
  try {
    loadVocabulary(path);
    ADD_FAILURE() << "loaded " << path;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(VocabularyFile, RoundTripIsBitIdentical) {
  const auto dir = urbanslam::test::scratchDir("vocabulary_round_trip");
  for (DescriptorType type : {DescriptorType::Sift, DescriptorType::Orb}) {
    const Vocabulary v = randomVocabulary(type);
    const std::string a = (dir / ("a_" + descriptorName(type) + ".voc")).string();
    const std::string b = (dir / ("b_" + descriptorName(type) + ".voc")).string();
    saveVocabulary(v, a);
    const Vocabulary loaded = loadVocabulary(a);
    saveVocabulary(loaded, b);
    EXPECT_EQ(readAll(a), readAll(b));
    const auto& x = v.data();
    const auto& y = loaded.data();
    EXPECT_EQ(x.centres, y.centres);
    EXPECT_EQ(x.first_child, y.first_child);
    EXPECT_EQ(x.child_count, y.child_count);
    EXPECT_EQ(x.word_of_node, y.word_of_node);
    EXPECT_EQ(x.node_of_word, y.node_of_word);
    EXPECT_EQ(x.idf, y.idf);
    EXPECT_EQ(x.inverse_norms, y.inverse_norms);
    EXPECT_EQ(x.training_images, y.training_images);
    EXPECT_EQ(loaded.descriptorType(), type);
  }
}

TEST(VocabularyFile, CorruptTruncatedOrForeignFilesAreRefused) {
  const auto dir = urbanslam::test::scratchDir("vocabulary_corrupt");
  const std::string good = (dir / "good.voc").string();
  saveVocabulary(randomVocabulary(DescriptorType::Orb), good);
  const std::string bytes = readAll(good);

  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  writeAll((dir / "flipped.voc").string(), flipped);
  expectRefused((dir / "flipped.voc").string(), "checksum");

  writeAll((dir / "truncated.voc").string(), bytes.substr(0, bytes.size() - 100));
  expectRefused((dir / "truncated.voc").string(), "truncated");

  std::string version = bytes;
  version[8] = 7;  // format version field
  writeAll((dir / "version.voc").string(), version);
  expectRefused((dir / "version.voc").string(), "version 7 is not supported");

  writeAll((dir / "text.voc").string(), "k=10 L=6 this is a DBoW2 text vocabulary\n");
  expectRefused((dir / "text.voc").string(), "not an urbanslam vocabulary");

  expectRefused((dir / "missing.voc").string(), "cannot open");
}

// A corrupt node count in the header is refused before the arrays are allocated (2^32 - 1
// nodes of a SIFT vocabulary would be 2.5 TB).
TEST(VocabularyFile, HeaderCountsMustMatchTheFileSize) {
  const auto dir = urbanslam::test::scratchDir("vocabulary_counts");
  const std::string good = (dir / "good.voc").string();
  saveVocabulary(randomVocabulary(DescriptorType::Sift), good);
  std::string bytes = readAll(good);
  const uint64_t nodes = (1ull << 32) - 1;
  std::memcpy(&bytes[8 + 4 * 4], &nodes, sizeof nodes);  // magic, version, type, branching, depth, then nodes
  writeAll((dir / "nodes.voc").string(), bytes);
  expectRefused((dir / "nodes.voc").string(), "nodes.voc: vocabulary file is truncated: its header declares 4294967295 nodes");
  writeAll((dir / "longer.voc").string(), readAll(good) + "extra");
  expectRefused((dir / "longer.voc").string(), "longer.voc: vocabulary file is corrupt: its header declares");
}
