#include "urbanslam/sim/CameraRenderer.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "urbanslam/sim/Random.h"
#include "urbanslam/sim/SurfaceTexture.h"

namespace urbanslam::sim {

namespace {

constexpr uint64_t kTagCamera = 50, kTagGround = 51;
constexpr double kDeg = M_PI / 180.0;
constexpr int kMaxLayers = 8;     // walls met by one column's ray (low objects let it go on)
constexpr double kFogTone = 212;  // the haze distant things fade into: the sky at the horizon

// Whatever stands as tall as a building ends the column's ray.
bool endsRay(SurfaceKind k) { return k == SurfaceKind::Facade || k == SurfaceKind::Featureless; }

// Standard normal values in a fixed table: pixel noise needs to be cheap, not perfect.
const std::array<float, 4096>& normalTable() {
  static const std::array<float, 4096> table = [] {
    std::array<float, 4096> t{};
    Rng r(12345);
    for (float& v : t) v = static_cast<float>(r.normal());
    return t;
  }();
  return table;
}

struct Layer {
  double range;
  Segment segment;
  double u;
};

}  // namespace

CameraRenderer::CameraRenderer(const CameraOptions& options, const WallRayCaster& walls, uint64_t seed)
    : options_(options), walls_(walls), seed_(hash64(seed, kTagCamera, options.noise_seed)), ground_seed_(hash64(seed, kTagGround)) {
  fx_ = options.width_px / 2.0 / std::tan(options.hfov_deg * kDeg / 2);
  cx_ = options.width_px / 2.0;
  cy_ = options.cy_px < 0 ? options.height_px / 2.0 : options.cy_px;
  bearing_.resize(static_cast<size_t>(options.width_px));
  for (int x = 0; x < options.width_px; ++x) bearing_[static_cast<size_t>(x)] = std::atan2(cx_ - (x + 0.5), fx_);
}

double CameraRenderer::columnBearing(int x) const { return bearing_[static_cast<size_t>(x)]; }

std::vector<double> CameraRenderer::columnRanges(const common::Pose2& camera) const {
  std::vector<double> out(bearing_.size());
  for (size_t x = 0; x < bearing_.size(); ++x) {
    const double a = camera.phi + bearing_[x];
    RayHit hit;
    out[x] = walls_.raycast({camera.x, camera.y}, {std::cos(a), std::sin(a)}, options_.max_range_m, hit) ? hit.range : kNoHit;
  }
  return out;
}

io::CameraImage CameraRenderer::render(uint64_t index, double timestamp, const common::Pose2& camera) const {
  const int w = options_.width_px, hgt = options_.height_px;
  const double ch = options_.height_m, fog = options_.fog_distance_m;
  auto pixels = std::make_shared<std::vector<uint8_t>>(static_cast<size_t>(w) * static_cast<size_t>(hgt));
  uint8_t* px = pixels->data();

  // Per row: the sky (brighter towards the horizon), or the ground's distance and haze.
  std::vector<float> sky(static_cast<size_t>(hgt)), ground_z(static_cast<size_t>(hgt)), ground_fog(static_cast<size_t>(hgt));
  for (int r = 0; r < hgt; ++r) {
    const double yc = r + 0.5;
    sky[static_cast<size_t>(r)] = static_cast<float>(kFogTone - 45 * std::clamp((cy_ - yc) / std::max(cy_, 1.0), 0.0, 1.0));
    if (yc > cy_) {
      const double z = fx_ * ch / (yc - cy_);
      ground_z[static_cast<size_t>(r)] = static_cast<float>(z);
      ground_fog[static_cast<size_t>(r)] = static_cast<float>(fog > 0 ? std::exp(-z / fog) : 1.0);
    }
  }
  const Vec2 o{camera.x, camera.y}, fwd{std::cos(camera.phi), std::sin(camera.phi)}, left{-fwd.y, fwd.x};
  const Vec2 sun{std::cos(35 * kDeg), std::sin(35 * kDeg)};

  std::vector<Layer> layers;
  std::vector<float> column(static_cast<size_t>(hgt));
  for (int x = 0; x < w; ++x) {
    const double bearing = bearing_[static_cast<size_t>(x)];
    const double a = camera.phi + bearing, cos_b = std::cos(bearing), lateral = std::tan(bearing);
    const Vec2 d{std::cos(a), std::sin(a)};
    layers.clear();
    double travelled = 0;
    for (int k = 0; k < kMaxLayers; ++k) {
      RayHit hit;
      if (!walls_.raycast(o + travelled * d, d, options_.max_range_m - travelled, hit)) break;
      layers.push_back({travelled + hit.range, hit.segment, hit.u_m});
      if (endsRay(hit.segment.look.kind)) break;
      travelled += hit.range + 1e-4;  // just past the wall, so it is not met again
    }
    // Sky and ground first, then the walls from the farthest to the nearest.
    for (int r = 0; r < hgt; ++r) {
      const auto ri = static_cast<size_t>(r);
      if (r + 0.5 <= cy_) {
        column[ri] = sky[ri];
        continue;
      }
      // Paving anchored to the world: 1 m cells of slightly varied tone, fading with distance.
      const double z = ground_z[ri];
      const Vec2 g = o + z * fwd + (z * lateral) * left;
      const auto gx = static_cast<int64_t>(std::floor(g.x)), gy = static_cast<int64_t>(std::floor(g.y));
      const double contrast = std::min(1.0, 10.0 / z);
      const double tone =
          100 + contrast * (static_cast<double>(
                                mix64(ground_seed_ ^ static_cast<uint64_t>(gx * 73856093) ^ static_cast<uint64_t>(gy * 19349663)) % 25) -
                            12);
      column[ri] = static_cast<float>(kFogTone + (tone - kFogTone) * ground_fog[ri]);
    }
    for (auto it = layers.rbegin(); it != layers.rend(); ++it) {
      const Segment& s = it->segment;
      const double z = it->range * cos_b;  // depth along the optical axis
      if (z <= 1e-6) continue;
      const double top = cy_ - fx_ * (s.look.height_m - ch) / z, foot = cy_ + fx_ * ch / z;
      const int r0 = std::max(0, static_cast<int>(std::ceil(top - 0.5)));
      const int r1 = std::min(hgt - 1, static_cast<int>(std::ceil(foot - 0.5)) - 1);
      if (r0 > r1) continue;
      // Lambert shading by a fixed sun on the side facing the camera: a wall keeps its brightness
      // from every viewpoint on its side.
      Vec2 n{-(s.b.y - s.a.y), s.b.x - s.a.x};
      const double nl = norm(n);
      if (nl > 0) n = (1 / nl) * n;
      if (dot(n, d) > 0) n = -1.0 * n;
      const double shade = 0.62 + 0.38 * std::max(0.0, dot(n, sun));
      const double f = fog > 0 ? std::exp(-it->range / fog) : 1.0;
      const float gain = static_cast<float>(shade * f), offset = static_cast<float>(kFogTone * (1 - f));
      const SurfaceTexture tex(s.look);
      const SurfaceTexture::Column col = tex.column(it->u);
      const double dh = z / fx_;
      for (int r = r0; r <= r1; ++r) {
        const double hh = ch + (cy_ - (r + 0.5)) * dh;
        column[static_cast<size_t>(r)] = gain * static_cast<float>(tex.at(col, hh)) + offset;
      }
    }
    for (int r = 0; r < hgt; ++r)
      px[static_cast<size_t>(r) * w + x] = static_cast<uint8_t>(std::clamp(column[static_cast<size_t>(r)], 0.f, 255.f) + 0.5f);
  }

  if (options_.noise_sigma > 0) {
    const auto& table = normalTable();
    Rng rng(hash64(seed_, kTagCamera, static_cast<int64_t>(index)));
    const float sigma = static_cast<float>(options_.noise_sigma);
    const size_t n = pixels->size();
    for (size_t i = 0; i < n;) {
      uint64_t bits = rng.next();
      for (int k = 0; k < 5 && i < n; ++k, ++i, bits >>= 12) {
        const float v = px[i] + sigma * table[bits & 4095u];
        px[i] = static_cast<uint8_t>(std::clamp(v, 0.f, 255.f) + 0.5f);
      }
    }
  }

  io::CameraImage img;
  img.timestamp = timestamp;
  img.label = options_.label;
  img.width = w;
  img.height = hgt;
  img.pixels = std::move(pixels);
  // The renderer's pixel centres sit at +0.5; OpenCV's at integers.
  img.calibration = io::CameraCalibration{fx_, fx_, cx_ - 0.5, cy_ - 0.5, cameraMount(options_)};
  return img;
}

}  // namespace urbanslam::sim
