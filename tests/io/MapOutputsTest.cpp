#include <gtest/gtest.h>

#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/maps/CSimplePointsMap.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/MapOutputs.h"

using namespace urbanslam;

namespace {

// Scans of the Intel excerpt placed at the log's reference (corrected) poses.
struct Excerpt {
  std::vector<io::LaserScan> scans;
  std::vector<io::StampedPose> reference;
  std::vector<io::PosedScan> posed() const {
    std::vector<io::PosedScan> out;
    for (size_t i = 0; i < scans.size(); ++i) out.push_back({reference[i].pose, &scans[i]});
    return out;
  }
};

Excerpt loadExcerpt() {
  Excerpt e;
  auto src = io::openDataSource(test::repoPath("rawlogs/intel-corrected-excerpt.log.gz"));
  io::Measurement m;
  while (src->next(m)) {
    if (auto* s = std::get_if<io::LaserScan>(&m)) e.scans.push_back(*s);
    if (auto* r = std::get_if<io::ReferencePose>(&m)) e.reference.push_back({r->timestamp, r->pose});
  }
  return e;
}

}  // namespace

// Median distance from the points of scan k+step to the nearest point of scan k, both placed at
// the reference poses.
double medianOverlapDistance(const Excerpt& e, size_t step) {
  std::vector<double> nn;
  for (size_t k = 0; k + step < e.scans.size(); k += 4) {
    const auto a = io::mapPoints({{e.reference[k].pose, &e.scans[k]}});
    const auto b = io::mapPoints({{e.reference[k + step].pose, &e.scans[k + step]}});
    for (size_t i = 0; i < b.size(); i += 5) {
      double best = 1e9;
      for (const auto& p : a) best = std::min<double>(best, std::hypot(p.x - b[i].x, p.y - b[i].y));
      nn.push_back(best);
    }
  }
  std::sort(nn.begin(), nn.end());
  return nn[nn.size() / 2];
}

// The beam geometry (start angle, resolution, direction) is right when scans placed at the
// reference poses land on the same walls; carmen2rawlog's 90° field of view smears them apart.
TEST(MapOutputs, ScansAtReferencePosesOverlap) {
  Excerpt e = loadExcerpt();
  const double right = medianOverlapDistance(e, 2);
  EXPECT_LT(right, 0.08);
  for (auto& s : e.scans) {
    s.angle_increment_rad /= 2;
    s.angle_min_rad /= 2;
  }
  const double wrong = medianOverlapDistance(e, 2);
  EXPECT_GT(wrong, 2 * right) << "the overlap measure cannot tell a wrong field of view: " << wrong;
  RecordProperty("median_right_m", std::to_string(right));
  RecordProperty("median_wrong_m", std::to_string(wrong));
}

TEST(MapOutputs, PlyReadBackByMrpt) {
  const Excerpt e = loadExcerpt();
  const auto pts = io::mapPoints(e.posed());
  ASSERT_GT(pts.size(), 5000u);
  const auto d = test::scratchDir("ply");
  for (auto enc : {io::PlyEncoding::BinaryLittleEndian, io::PlyEncoding::Ascii}) {
    const std::string f = (d / (enc == io::PlyEncoding::Ascii ? "a.ply" : "b.ply")).string();
    io::writePly(f, pts, enc);
    mrpt::maps::CSimplePointsMap m;
    ASSERT_TRUE(m.loadFromPlyFile(f));
    ASSERT_EQ(m.size(), pts.size());
    for (size_t i = 0; i < pts.size(); i += 97) {
      float x, y, z;
      m.getPoint(i, x, y, z);
      EXPECT_NEAR(x, pts[i].x, 1e-3);
      EXPECT_NEAR(y, pts[i].y, 1e-3);
    }
  }
}

// PCD as PCL reads a binary one: the header's lines up to DATA, then three floats per point.
TEST(MapOutputs, PcdHoldsThePointsBinaryAndXyzOneLinePerPoint) {
  const Excerpt e = loadExcerpt();
  const auto pts = io::mapPoints(e.posed(), 3);
  const auto d = test::scratchDir("pcd");
  io::writePcd((d / "m.pcd").string(), pts);
  io::writeXyz((d / "m.xyz").string(), pts);
  std::ifstream pcd(d / "m.pcd", std::ios::binary);
  std::string line;
  size_t declared = 0;
  std::vector<std::string> keys;
  while (std::getline(pcd, line)) {
    if (line.empty() || line[0] == '#') continue;
    keys.push_back(line.substr(0, line.find(' ')));
    if (keys.back() == "POINTS") declared = std::stoul(line.substr(7));
    if (keys.back() == "DATA") {
      EXPECT_EQ(line, "DATA binary");
      break;
    }
  }
  EXPECT_EQ(keys,
            (std::vector<std::string>{"VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "VIEWPOINT", "POINTS", "DATA"}));
  EXPECT_EQ(declared, pts.size());
  std::vector<float> body(3 * pts.size() + 1);
  pcd.read(reinterpret_cast<char*>(body.data()), static_cast<std::streamsize>(body.size() * sizeof(float)));
  ASSERT_EQ(static_cast<size_t>(pcd.gcount()), 3 * pts.size() * sizeof(float));  // nothing after the last point
  for (size_t i = 0; i < pts.size(); i += 101) {
    EXPECT_EQ(body[3 * i], pts[i].x);
    EXPECT_EQ(body[3 * i + 1], pts[i].y);
    EXPECT_EQ(body[3 * i + 2], pts[i].z);
  }
  std::ifstream xyz(d / "m.xyz");
  size_t n = 0;
  double x, y, z;
  while (xyz >> x >> y >> z) ++n;
  EXPECT_EQ(n, pts.size());
}

TEST(MapOutputs, SimpleMapLoadsInMrpt) {
  const Excerpt e = loadExcerpt();
  const auto d = test::scratchDir("simplemap");
  io::writeSimpleMap((d / "m.simplemap").string(), e.posed());
  mrpt::maps::CSimpleMap sm;
  ASSERT_TRUE(sm.loadFromFile((d / "m.simplemap").string()));
  ASSERT_EQ(sm.size(), e.scans.size());
  const auto& [pose, sf] = sm.get(10);
  EXPECT_NEAR(pose->getMeanVal().x(), e.reference[10].pose.x, 1e-9);
  EXPECT_EQ(sf->size(), 1u);
}

// `eval` reads the keyframe scans back from the .simplemap: same poses, ranges and validity, and
// an empty keyframe scan stays an empty entry, so entry k is still keyframe k.
TEST(MapOutputs, SimpleMapReadsBackScansAndPoses) {
  Excerpt e = loadExcerpt();
  e.scans[3] = io::LaserScan{};  // a keyframe without a scan
  const auto d = test::scratchDir("simplemap_read");
  io::writeSimpleMap((d / "m.simplemap").string(), e.posed());
  const auto back = io::readSimpleMap((d / "m.simplemap").string());
  ASSERT_EQ(back.size(), e.scans.size());
  EXPECT_TRUE(back[3].scan.ranges.empty());
  for (size_t i : {0u, 10u, 79u}) {
    EXPECT_NEAR(back[i].pose.x, e.reference[i].pose.x, 1e-9);
    EXPECT_NEAR(back[i].pose.y, e.reference[i].pose.y, 1e-9);
    EXPECT_NEAR(common::wrapToPi(back[i].pose.phi - e.reference[i].pose.phi), 0, 1e-9);
    ASSERT_EQ(back[i].scan.ranges.size(), e.scans[i].ranges.size());
    for (size_t k = 0; k < e.scans[i].ranges.size(); ++k) {
      EXPECT_EQ(back[i].scan.valid[k], e.scans[i].valid[k]) << "scan " << i << " beam " << k;
      if (e.scans[i].valid[k]) {
        EXPECT_NEAR(back[i].scan.ranges[k], e.scans[i].ranges[k], 1e-4);
      }
    }
    EXPECT_NEAR(back[i].scan.angle_increment_rad, e.scans[i].angle_increment_rad, 1e-7);
  }
  EXPECT_THROW(io::readSimpleMap((d / "missing.simplemap").string()), common::InputError);
}

TEST(MapOutputs, TumRoundTripAndGridYaml) {
  const Excerpt e = loadExcerpt();
  const auto d = test::scratchDir("tum");
  io::writeTum((d / "t.tum").string(), e.reference);
  const auto back = io::readTum((d / "t.tum").string());
  ASSERT_EQ(back.size(), e.reference.size());
  for (size_t i = 0; i < back.size(); ++i) {
    EXPECT_NEAR(back[i].timestamp, e.reference[i].timestamp, 1e-6);
    EXPECT_NEAR(back[i].pose.x, e.reference[i].pose.x, 1e-6);
    EXPECT_NEAR(common::wrapToPi(back[i].pose.phi - e.reference[i].pose.phi), 0, 1e-8);
  }
  const auto [w, h] = io::writeOccupancyGrid((d / "grid").string(), e.posed(), {});
  EXPECT_GT(w, 100);
  EXPECT_GT(h, 100);
  std::ifstream yaml(d / "grid.yaml");
  std::string all((std::istreambuf_iterator<char>(yaml)), {});
  EXPECT_NE(all.find("image: grid.png"), std::string::npos);
  EXPECT_NE(all.find("resolution: 0.05"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(d / "grid.png"));
}

// Logs are not always in time order (the Intel log has scans stamped earlier than the scan
// before them); a TUM file is a time series, so it is written sorted, keeping every pose.
TEST(MapOutputs, TumIsWrittenInTimeOrder) {
  const auto d = test::scratchDir("tum_order");
  io::writeTum((d / "t.tum").string(), {{2.0, {2, 0, 0}}, {1.0, {1, 0, 0}}, {3.0, {3, 0, 0}}, {1.0, {1.5, 0, 0}}});
  const auto back = io::readTum((d / "t.tum").string());
  ASSERT_EQ(back.size(), 4u);
  EXPECT_EQ(back[0].timestamp, 1.0);
  EXPECT_EQ(back[0].pose.x, 1.0);  // equal times keep their order
  EXPECT_EQ(back[1].pose.x, 1.5);
  EXPECT_EQ(back[2].timestamp, 2.0);
  EXPECT_EQ(back[3].timestamp, 3.0);
}

TEST(MapOutputs, TumValuesMustBeFiniteDecimalsInRange) {
  const auto d = test::scratchDir("tum_bad");
  const auto expectError = [&](const std::string& line, const std::string& fragment) {
    const std::string path = (d / "bad.tum").string();
    std::ofstream(path) << "# t x y z qx qy qz qw\n0 0 0 0 0 0 0 1\n" << line << "\n";
    try {
      io::readTum(path);
      ADD_FAILURE() << "no error for " << line;
    } catch (const common::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expectError("1 inf 0 0 0 0 0 1", "bad.tum:3: position 'inf' is not a number");
  expectError("1 0x10 0 0 0 0 0 1", "bad.tum:3: position '0x10' is not a number");
  expectError("1 0 1e8 0 0 0 0 1", "bad.tum:3: position 1e8 is out of range");
  expectError("nan 0 0 0 0 0 0 1", "bad.tum:3: timestamp 'nan'");
}

// The clouds a run writes are streamed from its keyframes' compact scans, one scan at a time;
// the reference is the whole cloud built from the same scans expanded, written by the writers
// that take a cloud: the files are the same, byte for byte, and so is the count.
TEST(MapOutputs, StreamedCloudsFromCompactScansEqualTheWholeCloud) {
  const Excerpt e = loadExcerpt();
  std::vector<io::CompactScan> compact;
  std::vector<io::LaserScan> expanded;
  for (const auto& s : e.scans) {
    compact.emplace_back(s);
    expanded.push_back(compact.back().expand());
  }
  std::vector<io::PosedScan> streamed, whole;
  for (size_t i = 0; i < e.scans.size(); ++i) {
    streamed.push_back({e.reference[i].pose, nullptr, &compact[i]});
    whole.push_back({e.reference[i].pose, &expanded[i]});
  }
  const int decimation = 3;
  const auto pts = io::mapPoints(whole, decimation);
  ASSERT_GT(pts.size(), 1000u);
  EXPECT_EQ(io::countMapPoints(streamed, decimation), pts.size());
  const auto d = test::scratchDir("streamed_clouds");
  const auto bytes = [](const std::filesystem::path& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  io::writePly((d / "whole.ply").string(), pts, io::PlyEncoding::BinaryLittleEndian);
  io::writePly((d / "streamed.ply").string(), streamed, decimation, io::PlyEncoding::BinaryLittleEndian);
  io::writePly((d / "whole_ascii.ply").string(), pts, io::PlyEncoding::Ascii);
  io::writePly((d / "streamed_ascii.ply").string(), streamed, decimation, io::PlyEncoding::Ascii);
  io::writePcd((d / "whole.pcd").string(), pts);
  io::writePcd((d / "streamed.pcd").string(), streamed, decimation);
  io::writeXyz((d / "whole.xyz").string(), pts);
  io::writeXyz((d / "streamed.xyz").string(), streamed, decimation);
  for (const char* ext : {".ply", "_ascii.ply", ".pcd", ".xyz"}) {
    const std::string a = bytes(d / (std::string("whole") + ext)), b = bytes(d / (std::string("streamed") + ext));
    EXPECT_GT(a.size(), 1000u) << ext;
    EXPECT_TRUE(a == b) << ext << " differs";
  }
}

// A mask leaves out exactly the points it does not keep, before decimation: the reference is
// the whole cloud filtered by the same rule, then decimated by hand. Files streamed with the
// mask equal the writers' output for that reference cloud, and the header counts agree.
TEST(MapOutputs, MaskedCloudsKeepExactlyTheMaskedPoints) {
  const Excerpt e = loadExcerpt();
  const auto posed = e.posed();
  const auto all = io::mapPoints(posed);
  ASSERT_GT(all.size(), 5000u);
  const auto keep = [](size_t i) { return i % 7 != 3 && (i / 100) % 5 != 2; };
  io::PointMask mask;
  for (size_t i = 0; i < all.size(); ++i) mask.push(keep(i));
  const int decimation = 2;
  std::vector<io::MapPoint> reference;
  size_t kept = 0;
  for (size_t i = 0; i < all.size(); ++i)
    if (keep(i) && kept++ % decimation == 0) reference.push_back(all[i]);
  EXPECT_EQ(mask.kept(), kept);
  EXPECT_EQ(io::countMapPoints(posed, decimation, &mask), reference.size());
  const auto masked = io::mapPoints(posed, decimation, &mask);
  ASSERT_EQ(masked.size(), reference.size());
  for (size_t i = 0; i < masked.size(); ++i) ASSERT_TRUE(masked[i].x == reference[i].x && masked[i].y == reference[i].y) << i;
  const auto d = test::scratchDir("masked_clouds");
  const auto bytes = [](const std::filesystem::path& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  io::writePly((d / "reference.ply").string(), reference, io::PlyEncoding::BinaryLittleEndian);
  io::writePly((d / "masked.ply").string(), posed, decimation, io::PlyEncoding::BinaryLittleEndian, &mask);
  io::writePcd((d / "reference.pcd").string(), reference);
  io::writePcd((d / "masked.pcd").string(), posed, decimation, &mask);
  EXPECT_TRUE(bytes(d / "reference.ply") == bytes(d / "masked.ply"));
  EXPECT_TRUE(bytes(d / "reference.pcd") == bytes(d / "masked.pcd"));
}

// readPly against MRPT's own PLY writer (an independent implementation), and against ours in
// both encodings; a cut file gets an error naming it.
TEST(MapOutputs, ReadPlyReadsMrptsAndOurFiles) {
  const Excerpt e = loadExcerpt();
  const auto pts = io::mapPoints(e.posed(), 5);
  ASSERT_GT(pts.size(), 1000u);
  const auto d = test::scratchDir("read_ply");
  mrpt::maps::CSimplePointsMap m;
  for (const auto& p : pts) m.insertPoint(p.x, p.y, p.z);
  const std::string mrpt_file = (d / "mrpt.ply").string();
  ASSERT_TRUE(m.saveToPlyFile(mrpt_file, false));
  for (const std::string& f : {mrpt_file, (d / "b.ply").string(), (d / "a.ply").string()}) {
    if (f != mrpt_file) io::writePly(f, pts, f == (d / "a.ply").string() ? io::PlyEncoding::Ascii : io::PlyEncoding::BinaryLittleEndian);
    const auto back = io::readPly(f);
    ASSERT_EQ(back.size(), pts.size()) << f;
    for (size_t i = 0; i < pts.size(); ++i)
      ASSERT_TRUE(std::abs(back[i].x - pts[i].x) < 1e-3 && std::abs(back[i].y - pts[i].y) < 1e-3) << f << " " << i;
  }
  const std::string cut = (d / "cut.ply").string();
  io::writePly(cut, pts, io::PlyEncoding::BinaryLittleEndian);
  std::filesystem::resize_file(cut, std::filesystem::file_size(cut) - 30);
  try {
    io::readPly(cut);
    ADD_FAILURE() << "no error for a cut file";
  } catch (const common::InputError& x) {
    EXPECT_NE(std::string(x.what()).find("cut.ply: truncated"), std::string::npos) << x.what();
  }
}
