// g2o / TORO pose-graph reading and writing.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "urbanslam/common/Error.h"
#include "urbanslam/esdf/PoseGraphIO.h"

namespace urbanslam::esdf {
namespace {

const char* kG2o =
    "VERTEX_SE2 0 0 0 0\n"
    "VERTEX_SE2 1 1.5 0.25 0.1\n"
    "\n"
    "VERTEX_SE2 2 2.5 0.5 -3.0\n"
    "EDGE_SE2 0 1 1.5 0.25 0.1 11 12 13 22 23 33\n"
    "EDGE_SE2 1 2 1.0 0.5 3.1 44.6 -7.9 0.1 376.5 0.2 9745.8\n"
    "# a comment\n"
    "EDGE_SE2 2 0 -2.5 0.5 3.0 1 0 0 1 0 1\n";

std::filesystem::path tempDir() {
  auto d = std::filesystem::temp_directory_path() / ("urbanslam_esdf_io_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

TEST(PoseGraphIO, ParsesG2oWithBlankLinesAndComments) {
  const PoseGraph g = parsePoseGraph(kG2o, "mem.g2o");
  ASSERT_EQ(g.vertices.size(), 3u);
  ASSERT_EQ(g.edges.size(), 3u);
  EXPECT_EQ(g.format, PoseGraphFormat::G2o);
  EXPECT_EQ(g.vertices[2].pose, Vec3(2.5, 0.5, -3.0));
  const Mat3& i = g.edges[0].information;
  // g2o order: upper triangle row by row.
  EXPECT_EQ(i(0, 0), 11);
  EXPECT_EQ(i(0, 1), 12);
  EXPECT_EQ(i(0, 2), 13);
  EXPECT_EQ(i(1, 1), 22);
  EXPECT_EQ(i(1, 2), 23);
  EXPECT_EQ(i(2, 2), 33);
  EXPECT_EQ(i, i.transpose());
}

TEST(PoseGraphIO, ParsesEdgesOnlyFile) {
  const PoseGraph g = parsePoseGraph("\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n\nEDGE_SE2 1 2 1 0 0 1 0 0 1 0 1\n", "e.g2o");
  EXPECT_TRUE(g.vertices.empty());
  EXPECT_EQ(g.edges.size(), 2u);
}

TEST(PoseGraphIO, ToroInformationOrderIsFfFsSsRrFrSr) {
  const PoseGraph g = parsePoseGraph("VERTEX2 0 1 2 0.5\nEDGE2 0 1 1 0 0.1 11 12 22 33 13 23\n", "t.graph");
  EXPECT_EQ(g.format, PoseGraphFormat::Toro);
  const Mat3& i = g.edges[0].information;
  EXPECT_EQ(i(0, 0), 11);
  EXPECT_EQ(i(0, 1), 12);
  EXPECT_EQ(i(1, 1), 22);
  EXPECT_EQ(i(2, 2), 33);
  EXPECT_EQ(i(0, 2), 13);
  EXPECT_EQ(i(1, 2), 23);
  EXPECT_EQ(i(2, 0), 13);
}

void expectSame(const PoseGraph& a, const PoseGraph& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.edges.size(), b.edges.size());
  for (size_t k = 0; k < a.vertices.size(); ++k) {
    EXPECT_EQ(a.vertices[k].id, b.vertices[k].id);
    EXPECT_EQ(a.vertices[k].pose, b.vertices[k].pose);  // %.17g round-trips exactly
  }
  for (size_t k = 0; k < a.edges.size(); ++k) {
    EXPECT_EQ(a.edges[k].from, b.edges[k].from);
    EXPECT_EQ(a.edges[k].to, b.edges[k].to);
    EXPECT_EQ(a.edges[k].measurement, b.edges[k].measurement);
    EXPECT_EQ(a.edges[k].information, b.edges[k].information);
  }
}

TEST(PoseGraphIO, RoundTripsThroughG2oAndToroFiles) {
  const PoseGraph g = parsePoseGraph(kG2o, "mem.g2o");
  const auto dir = tempDir();
  const std::string g2o = (dir / "a.g2o").string(), toro = (dir / "a.graph").string();
  writePoseGraph(g, g2o, PoseGraphFormat::G2o);
  writePoseGraph(g, toro, PoseGraphFormat::Toro);
  expectSame(g, readPoseGraph(g2o));
  const PoseGraph t = readPoseGraph(toro);
  EXPECT_EQ(t.format, PoseGraphFormat::Toro);
  expectSame(g, t);
  // g2o -> TORO -> g2o text is stable.
  EXPECT_EQ(formatPoseGraph(readPoseGraph(toro), PoseGraphFormat::G2o), formatPoseGraph(g, PoseGraphFormat::G2o));
  std::filesystem::remove_all(dir);
}

TEST(PoseGraphIO, MalformedInputNamesFileAndLine) {
  try {
    parsePoseGraph("VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 1 2 1 0 0 1 0\n", "bad.g2o");
    FAIL() << "expected InputError";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.g2o:3:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parsePoseGraph("VERTEX_SE2 0 0 zero 0\n", "x"), common::InputError);
  EXPECT_THROW(parsePoseGraph("VERTEX_SE2 0 0 +-1 0\n", "x"), common::InputError);
  EXPECT_THROW(parsePoseGraph("VERTEX_SE2 0 0 nan 0\n", "x"), common::InputError);
  EXPECT_EQ(parsePoseGraph("VERTEX_SE2 0 +1.5 -2e0 0\n", "x").vertices.at(0).pose.x(), 1.5);  // signs as strtod took them
  EXPECT_THROW(parsePoseGraph("EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1 7\n", "x"), common::InputError);
  EXPECT_THROW(parsePoseGraph("EDGE_SE2 0 1 1 0 0 -1 0 0 1 0 1\n", "x"), common::InputError);
  EXPECT_THROW(parsePoseGraph("EDGE_SE2 0 1 1 0 0 1 2 0 1 0 1\n", "x"), common::InputError);  // indefinite
  EXPECT_THROW(parsePoseGraph("just text\n", "x"), common::InputError);
  EXPECT_THROW(readPoseGraph("/nonexistent/graph.g2o"), common::InputError);
}

TEST(PoseGraphIO, ReadsGzipAndRejectsTruncatedGzip) {
  const std::string gz = std::string(URBANSLAM_SHARED_DATA_DIR) + "/pose_graphs_2d/se-sync/city10000.g2o.gz";
  if (!std::filesystem::exists(gz)) GTEST_SKIP() << "shared data absent: " << gz;
  const PoseGraph g = readPoseGraph(gz);
  EXPECT_EQ(g.edges.size(), 20687u);
  // Truncate a copy in the middle: the reader must not return a partial graph silently.
  const auto dir = tempDir();
  const auto cut = dir / "cut.g2o.gz";
  {
    std::ifstream in(gz, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream out(cut, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  EXPECT_THROW(readPoseGraph(cut.string()), common::InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace urbanslam::esdf
