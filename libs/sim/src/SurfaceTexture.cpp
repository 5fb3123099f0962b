#include "urbanslam/sim/SurfaceTexture.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/sim/Random.h"

namespace urbanslam::sim {

namespace {

constexpr uint64_t kTagTexture = 60, kTagWindow = 61, kTagShop = 62, kTagLetter = 63, kTagBlock = 64, kTagDisplay = 65, kTagStain = 66,
                   kTagHeight = 67, kTagGraffiti = 68;

int floorInt(double v) { return static_cast<int>(std::floor(v)); }
int mod(int a, int b) { return ((a % b) + b) % b; }
uint8_t clampTone(int v) { return static_cast<uint8_t>(std::clamp(v, 0, 255)); }
// A tone that stands out against `base` (dark on light walls, light on dark ones).
int contrasting(int base, Rng& r) { return base > 128 ? r.uniformInt(15, 70) : r.uniformInt(185, 245); }
uint64_t h(uint32_t id, uint64_t tag, int64_t a = 0, int64_t b = 0, int64_t c = 0) { return hash64(id, tag, a, b, c); }
// Pseudo-letter bit (4 columns x 5 rows) of letter `letter` in a sign: blocky glyphs with many
// corners, the same wherever the sign is seen from.
bool glyphBit(uint32_t id, int sign, int letter, int row, int col) {
  const uint64_t g = h(id, kTagLetter, sign, letter);
  return (g >> (row * 4 + col)) & 1u;
}

}  // namespace

SurfaceTexture::SurfaceTexture(const SurfaceLook& look) : look_(look) {
  if (look.kind != SurfaceKind::Facade && look.kind != SurfaceKind::Pillar) {
    Rng r(h(look.id, kTagTexture));
    wall_ = r.uniformInt(70, 190);
    accent_ = contrasting(wall_, r);
    return;
  }
  Rng r(h(look.id, kTagTexture));
  floor_h_ = r.uniform(3.0, 3.6);
  ground_h_ = r.uniform(3.9, 4.6);
  bay_w_ = r.uniform(2.2, 3.4);
  bay_off_ = r.uniform(0, bay_w_);
  win_w_ = bay_w_ * r.uniform(0.4, 0.6);
  win_h_ = floor_h_ * r.uniform(0.42, 0.56);
  sill_ = r.uniform(0.8, 1.0);
  frame_w_ = r.uniform(0.08, 0.14);
  cornice_h_ = r.uniform(0.6, 1.0);
  material_ = r.uniformInt(0, 3);
  block_h_ = r.uniform(0.28, 0.45);
  block_w_ = block_h_ * r.uniform(1.6, 2.6);
  pilaster_every_ = r.chance(0.4) ? r.uniformInt(2, 4) : 0;
  shops_ = r.chance(0.7);
  shop_bays_ = r.uniformInt(2, 4);
  door_every_ = r.uniformInt(2, 4);
  mullions_ = r.chance(0.6);
  wall_ = r.uniformInt(80, 190);
  frame_tone_ = contrasting(wall_, r);
  glass_ = r.uniformInt(20, 60);
  accent_ = wall_ > 135 ? wall_ - r.uniformInt(40, 75) : wall_ + r.uniformInt(40, 75);
  cornice_tone_ = contrasting(wall_, r);
}

double facadeHeight(uint32_t id, SurfaceKind kind) {
  Rng r(h(id, kTagHeight));
  switch (kind) {
    case SurfaceKind::Facade:
    case SurfaceKind::Pillar: {
      const SurfaceTexture t({id, SurfaceKind::Facade, 0.f});  // floors and cornice fit the height exactly
      return t.groundFloorHeight() + r.uniformInt(1, 5) * t.floorHeight() + t.corniceHeight();
    }
    case SurfaceKind::Featureless:
      return r.uniform(5.0, 12.0);
    case SurfaceKind::Tree:
      return r.uniform(4.0, 6.0);
    case SurfaceKind::LampPost:
      return r.uniform(5.0, 6.0);
    case SurfaceKind::ParkedCar:
      return r.uniform(1.4, 1.6);
    case SurfaceKind::Barrier:
      return r.uniform(2.5, 3.5);
    case SurfaceKind::Fountain:
      return r.uniform(0.8, 1.2);
    case SurfaceKind::Bench:
      return r.uniform(0.45, 0.55);
    case SurfaceKind::Island:
      return r.uniform(0.9, 1.3);  // a planted kerb, hedge on top
  }
  return 3.0;
}

SurfaceTexture::Column SurfaceTexture::column(double u) const {
  Column c;
  c.u = u;
  c.coarse = h(look_.id, kTagStain, floorInt(u / 1.3));
  if (look_.kind != SurfaceKind::Facade) return c;
  const double x = u - bay_off_;
  c.bay = floorInt(x / bay_w_);
  c.bay_u = x - c.bay * bay_w_;
  const double wl = (bay_w_ - win_w_) / 2;
  c.window = c.bay_u >= wl && c.bay_u < wl + win_w_;
  c.frame = c.window && (c.bay_u < wl + frame_w_ || c.bay_u >= wl + win_w_ - frame_w_);
  c.mullion = mullions_ && c.window && std::fabs(c.bay_u - bay_w_ / 2) < frame_w_ * 0.5;
  c.pilaster = pilaster_every_ > 0 && mod(c.bay, pilaster_every_) == 0 && c.bay_u < 0.45;
  c.door = mod(c.bay, door_every_) == 0 && std::fabs(c.bay_u - bay_w_ / 2) < 0.55;
  c.shop = c.bay >= 0 ? c.bay / shop_bays_ : -((-c.bay + shop_bays_ - 1) / shop_bays_);
  // Sign letters: 0.75 m a letter (4 bit columns of 0.15 m and a gap), margins at the shop's ends.
  const double shop_w = shop_bays_ * bay_w_, su = x - c.shop * shop_w;
  if (su > 0.4 && su < shop_w - 0.4) {
    c.letter = floorInt((su - 0.4) / 0.75);
    const int lc = floorInt((su - 0.4 - c.letter * 0.75) / 0.15);
    c.letter_col = lc < 4 ? lc : -1;
  }
  c.block_even = floorInt(u / block_w_);
  c.block_u_even = u - c.block_even * block_w_;
  c.block_odd = floorInt((u + block_w_ / 2) / block_w_);
  c.block_u_odd = u + block_w_ / 2 - c.block_odd * block_w_;
  return c;
}

uint8_t SurfaceTexture::material(const Column& c, double hh) const {
  switch (material_) {
    case 0: {  // stone blocks in staggered courses
      const int row = floorInt(hh / block_h_);
      const bool even = (row & 1) == 0;
      const double bu = even ? c.block_u_even : c.block_u_odd, bv = hh - row * block_h_;
      if (bu < 0.04 || bv < 0.04) return clampTone(wall_ + (wall_ > 128 ? -45 : 45));
      return clampTone(wall_ + static_cast<int>(h(look_.id, kTagBlock, even ? c.block_even : c.block_odd, row) % 31) - 15);
    }
    case 1: {  // panels, half a bay by half a floor, with dark joints
      const double pw = bay_w_ / 2, ph = floor_h_ / 2;
      const int pu = floorInt(c.u / pw), pv = floorInt(hh / ph);
      if (c.u - pu * pw < 0.05 || hh - pv * ph < 0.05) return clampTone(wall_ - 50);
      return clampTone(wall_ + static_cast<int>(h(look_.id, kTagBlock, pu, pv) % 41) - 20);
    }
    case 2: {  // plaster with large stains
      const int sv = floorInt(hh / 1.1);
      return clampTone(wall_ + static_cast<int>(mix64(c.coarse ^ static_cast<uint64_t>(sv)) % 17) - 8);
    }
    default: {  // rusticated courses: dark grooves, each course its own tone
      const int row = floorInt(hh / block_h_);
      if (hh - row * block_h_ < 0.05) return clampTone(wall_ - 55);
      return clampTone(wall_ + static_cast<int>(h(look_.id, kTagBlock, row) % 25) - 12);
    }
  }
}

uint8_t SurfaceTexture::facade(const Column& c, double hh) const {
  const double top = look_.height_m;
  if (hh >= top - cornice_h_) {
    const double v = hh - (top - cornice_h_);
    if (v < 0.25) return std::fmod(c.u + 1000.0, 0.4) < 0.2 ? clampTone(cornice_tone_) : clampTone(wall_);  // dentils
    if (v < 0.33) return clampTone(accent_);
    return clampTone(cornice_tone_);
  }
  if (hh < ground_h_) {
    if (c.pilaster) return clampTone(accent_);
    if (shops_) {
      const double sign0 = ground_h_ - 1.15, sign1 = ground_h_ - 0.25;
      if (hh >= sign0 && hh < sign1) {
        const uint64_t s = h(look_.id, kTagShop, c.shop);
        const int bg = 30 + static_cast<int>(s % 200);
        const int fg = bg > 128 ? bg - 110 : bg + 110;
        const int row = floorInt((hh - sign0 - 0.075) / 0.15);
        if (c.letter_col < 0 || row < 0 || row > 4) return clampTone(bg);
        return clampTone(glyphBit(look_.id, c.shop, c.letter, 4 - row, c.letter_col) ? fg : bg);
      }
      if (hh >= sign1 || hh >= sign0 - 0.2) return clampTone(accent_);
      if (c.door && hh < 2.3) {
        const double du = std::fabs(c.bay_u - bay_w_ / 2);
        if (du > 0.45 || hh > 2.2) return clampTone(frame_tone_);
        return clampTone((du < 0.05 || std::fabs(hh - 1.1) < 0.05) ? glass_ + 60 : glass_);
      }
      if (hh < 0.5) return clampTone(accent_);  // plinth under the shop window
      if (c.bay_u < 0.15 || c.bay_u > bay_w_ - 0.15 || hh < 0.6) return clampTone(frame_tone_);
      if (hh < 1.6) {  // goods on display: a grid of boxes of varied tone
        const int gu = floorInt(c.u / 0.3), gv = floorInt((hh - 0.6) / 0.25);
        const uint64_t g = h(look_.id, kTagDisplay, gu, gv);
        return clampTone(g & 1 ? glass_ + 40 + static_cast<int>((g >> 8) % 160) : glass_);
      }
      return clampTone(glass_ + static_cast<int>((hh - 1.6) * 25));  // glass, lighter upwards
    }
    if (c.door && hh < 2.4) {
      const double du = std::fabs(c.bay_u - bay_w_ / 2);
      if (du > 0.45 || hh > 2.3) return clampTone(frame_tone_);
      return clampTone(std::fabs(hh - 1.2) < 0.06 ? glass_ + 50 : glass_ + 10);
    }
  } else {
    const int f = floorInt((hh - ground_h_) / floor_h_);
    const double v = hh - ground_h_ - f * floor_h_;
    if (v < 0.18) return clampTone(accent_);  // string course
    if (c.pilaster) return clampTone(c.bay_u > 0.38 ? accent_ - 30 : accent_);
    if (c.window && v >= sill_ - 0.12 && v < sill_) return clampTone(accent_);  // sill
    if (c.window && v >= sill_ && v < sill_ + win_h_) {
      const double wv = v - sill_;
      if (c.frame || c.mullion || wv < frame_w_ || wv >= win_h_ - frame_w_ || (mullions_ && std::fabs(wv - win_h_ * 0.62) < frame_w_ / 2))
        return clampTone(frame_tone_);
      const uint64_t w = h(look_.id, kTagWindow, c.bay, f);
      switch (w % 5) {
        case 0:
          return clampTone(175 + static_cast<int>((w >> 8) % 60));  // a lit room
        case 1: {                                                   // a blind pulled part way down
          const double down = 0.25 + 0.6 * unitFromHash(w);
          if (wv > win_h_ * (1 - down)) return clampTone(std::fmod(wv, 0.16) < 0.03 ? 120 : 200);
          return clampTone(glass_);
        }
        case 2: {  // curtains at both sides
          const double mid = std::fabs(c.bay_u - bay_w_ / 2) / (win_w_ / 2);
          return clampTone(mid > 0.55 ? 150 + static_cast<int>((w >> 12) % 80) : glass_);
        }
        default:  // dark glass with the reflection of the sky towards the top
          return clampTone(glass_ + static_cast<int>(wv / win_h_ * 45));
      }
    }
  }
  return material(c, hh);
}

uint8_t SurfaceTexture::at(const Column& c, double hh) const {
  switch (look_.kind) {
    case SurfaceKind::Facade:
      return facade(c, hh);
    case SurfaceKind::Featureless:
      if (hh < 0.4) return clampTone(wall_ - 25);  // plinth
      return clampTone(wall_ + static_cast<int>(mix64(c.coarse ^ static_cast<uint64_t>(floorInt(hh / 2.5))) % 7) - 3);
    case SurfaceKind::Pillar:
      if (hh < 0.5 || hh > look_.height_m - 0.4) return clampTone(accent_);
      return clampTone(std::fmod(c.u + 100.0, 0.25) < 0.125 ? cornice_tone_ : cornice_tone_ - 25);  // fluting
    case SurfaceKind::Tree:
      return clampTone(55 + static_cast<int>(h(look_.id, kTagBlock, floorInt(c.u / 0.08), floorInt(hh / 0.3)) % 45));
    case SurfaceKind::LampPost:
      if (hh > look_.height_m - 0.5) return 235;
      return std::fabs(hh - 2.6) < 0.25 ? 200 : 55;
    case SurfaceKind::ParkedCar: {
      const int body = 40 + static_cast<int>(look_.id % 180);
      if (hh < 0.35) return 25;  // tyres and the shadow under the car
      if (hh < 0.85) return clampTone(std::fabs(hh - 0.6) < 0.03 ? body - 40 : body);
      if (hh < 0.93) return clampTone(body + 35);
      if (hh > look_.height_m - 0.08) return clampTone(body);
      return std::fmod(c.u + 100.0, 1.6) < 0.18 ? clampTone(body) : 45;  // windows between pillars
    }
    case SurfaceKind::Barrier: {
      const int panel = floorInt(c.u / 2.4);
      if (c.u - panel * 2.4 < 0.06) return clampTone(wall_ - 60);
      const uint64_t g = h(look_.id, kTagGraffiti, panel);
      if (g % 3 == 0 && hh > 0.6 && hh < 2.1) {  // graffiti: big pseudo-letters
        const double lu = c.u - panel * 2.4 - 0.2;
        const int letter = floorInt(lu / 0.6), col = floorInt((lu - letter * 0.6) / 0.12), row = floorInt((hh - 0.6) / 0.3);
        if (lu >= 0 && letter < 3 && col < 4 && glyphBit(look_.id, panel, letter, row, col))
          return clampTone(static_cast<int>((g >> 20) % 2 ? 30 : 230));
      }
      return clampTone(wall_ + static_cast<int>(g % 21) - 10);
    }
    case SurfaceKind::Fountain:
      if (hh > look_.height_m - 0.15) return 215;
      return std::fmod(c.u + 100.0, 0.6) < 0.05 ? 110 : 170;
    case SurfaceKind::Bench:
      return std::fmod(c.u + 100.0, 0.5) < 0.04 || hh < 0.1 ? 40 : clampTone(wall_);  // slats on dark legs
    case SurfaceKind::Island:
      if (hh < 0.25) return 200;  // the kerb stone
      return clampTone(50 + static_cast<int>(h(look_.id, kTagBlock, floorInt(c.u / 0.1), floorInt(hh / 0.1)) % 50));
  }
  return 128;
}

}  // namespace urbanslam::sim
