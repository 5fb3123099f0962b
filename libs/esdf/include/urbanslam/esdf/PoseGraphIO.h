#pragma once
// 2D pose-graph files: g2o (VERTEX_SE2 / EDGE_SE2) and TORO / old hog-man (VERTEX2 / EDGE2).
// Reading accepts files with edges only, blank lines, '#' comments, and gzip-compressed files
// (.gz); unknown tags (FIX, other vertex types) are skipped. Malformed lines throw
// common::InputError("FILE:LINE: what").
#include <string>
#include <vector>

#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::esdf {

enum class PoseGraphFormat { G2o, Toro };

struct PoseGraphVertex {
  long id;
  Vec3 pose;
};

struct PoseGraphEdge {
  long from, to;
  Vec3 measurement;  // pose of `to` in the frame of `from`
  Mat3 information;  // in (x, y, phi) order, symmetric
  long line = 0;     // of the file it was read from (0: not read from a file)
};

struct PoseGraph {
  std::vector<PoseGraphVertex> vertices;  // may be empty (edges-only files)
  std::vector<PoseGraphEdge> edges;
  PoseGraphFormat format = PoseGraphFormat::G2o;  // format of the file it was read from
  std::string name = "pose graph";                // the file it was read from, for messages
};

PoseGraph readPoseGraph(const std::string& path);
// Parses text (for tests); `name` is used in error messages.
PoseGraph parsePoseGraph(const std::string& text, const std::string& name);

// Writes atomically (common::AtomicFile). TORO's information order is ff fs ss rr fr sr.
void writePoseGraph(const PoseGraph& graph, const std::string& path, PoseGraphFormat format);
std::string formatPoseGraph(const PoseGraph& graph, PoseGraphFormat format);

// Sum over edges of e' Omega e with e = ⊖z ⊕ (⊖x_from ⊕ x_to) (the g2o / MRPT chi2), for
// poses given by vertex id -> index in `poses` (ids must be 0..n-1 after `indexOf`).
double poseGraphChi2(const PoseGraph& graph, const std::vector<Vec3>& poses_by_vertex_index, const std::vector<long>& vertex_ids);

}  // namespace urbanslam::esdf
