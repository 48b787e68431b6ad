// Deterministic procedural hallway textures (see textures.h).
//
// Every texture is painted in float BGR (grey levels 0..255) on a Canvas that converts metres to
// texels, then a "light" field (low-frequency shading + fine plaster texture + per-texel grain)
// is added and the result rounded to 8 bits. All randomness comes from sim::SplitMix64 streams
// (one per wall, door, object, tile ...) and from integer-hashed value noise; every random draw
// is its own statement so that no unspecified argument evaluation order can change a texture.
#include "sim/textures.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "sim/random.h"

namespace sim {
namespace {

using Colour = cv::Vec3f;  // B, G, R in grey levels (0..255)

// ---------------------------------------------------------------------------------------------
// Randomness.

// A SplitMix64 stream with the draws the painters need.
class Rng {
 public:
  explicit Rng(uint64_t seed) : gen_(seed) {}
  double Uniform() { return gen_.Uniform(); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * gen_.Uniform(); }
  // Integer in [lo, hi], both included.
  int Int(int lo, int hi) {
    return lo + static_cast<int>(gen_.Next() % static_cast<uint64_t>(hi - lo + 1));
  }
  bool Chance(double p) { return gen_.Uniform() < p; }
  // Seed of an independent child stream.
  uint64_t Fork() { return gen_.Next(); }

 private:
  SplitMix64 gen_;
};

// SplitMix64's finaliser: a bijective 64-bit mix.
inline uint64_t Mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Hash of a lattice point, uniform in [-1, 1).
inline float HashSigned(uint64_t seed, int64_t x, int64_t y) {
  const uint64_t h = Mix64(seed ^ Mix64(static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ull +
                                        static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4Full));
  return static_cast<float>(h >> 40) * (2.0f / 16777216.0f) - 1.0f;
}

// ---------------------------------------------------------------------------------------------
// Scalar fields (CV_32FC1). `origin` is the global texel of field(0, 0), so that the fields of
// neighbouring regions computed with the same seed join up.

// Adds amplitude * value noise: lattice values in [-1, 1] every cell_x texels horizontally and
// cell_y vertically, blended with a smoothstep.
void AddValueNoise(cv::Mat1f* field, cv::Point origin, uint64_t seed, double cell_x, double cell_y,
                   float amplitude) {
  if (amplitude == 0.f || field->empty()) return;
  cell_x = std::max(cell_x, 1.0);
  cell_y = std::max(cell_y, 1.0);
  const int cols = field->cols;
  std::vector<int> ix(cols);
  std::vector<float> wx(cols);
  for (int c = 0; c < cols; ++c) {
    const double u = (origin.x + c + 0.5) / cell_x;
    const double fl = std::floor(u);
    ix[c] = static_cast<int>(fl);
    const float t = static_cast<float>(u - fl);
    wx[c] = t * t * (3.f - 2.f * t);
  }
  const int i0 = ix[0];
  const int n = ix[cols - 1] - i0 + 2;
  std::vector<float> top(n), bottom(n);
  int64_t current_j = INT64_MIN;
  for (int r = 0; r < field->rows; ++r) {
    const double v = (origin.y + r + 0.5) / cell_y;
    const double fl = std::floor(v);
    const int64_t j = static_cast<int64_t>(fl);
    if (j != current_j) {
      for (int k = 0; k < n; ++k) {
        top[k] = HashSigned(seed, i0 + k, j);
        bottom[k] = HashSigned(seed, i0 + k, j + 1);
      }
      current_j = j;
    }
    float ty = static_cast<float>(v - fl);
    ty = ty * ty * (3.f - 2.f * ty);
    float* row = field->ptr<float>(r);
    for (int c = 0; c < cols; ++c) {
      const int k = ix[c] - i0;
      const float a = top[k] + wx[c] * (top[k + 1] - top[k]);
      const float b = bottom[k] + wx[c] * (bottom[k + 1] - bottom[k]);
      row[c] += amplitude * (a + ty * (b - a));
    }
  }
}

// Adds fractal value noise of `octaves` octaves (cell halving, amplitude halving per octave),
// scaled so that its peak is `amplitude`.
void AddFbm(cv::Mat1f* field, cv::Point origin, uint64_t seed, double cell_px, int octaves,
            float amplitude) {
  float norm = 0.f;
  for (int k = 0; k < octaves; ++k) norm += std::ldexp(1.f, -k);
  for (int k = 0; k < octaves; ++k) {
    const double cell = cell_px * std::ldexp(1.0, -k);
    AddValueNoise(field, origin, Mix64(seed + 101 * k), cell, cell,
                  amplitude * std::ldexp(1.f, -k) / norm);
  }
}

// Adds independent per-texel noise uniform in [-amplitude, amplitude).
void AddGrain(cv::Mat1f* field, cv::Point origin, uint64_t seed, float amplitude) {
  if (amplitude == 0.f) return;
  for (int r = 0; r < field->rows; ++r) {
    float* row = field->ptr<float>(r);
    for (int c = 0; c < field->cols; ++c)
      row[c] += amplitude * HashSigned(seed, origin.x + c, origin.y + r);
  }
}

// Two passes of a box filter of radius `radius` texels (close to a Gaussian of
// sigma ~ 0.8 radius), zero outside; fixed summation order.
void SoftenMask(cv::Mat1f* mask, int radius) {
  if (radius <= 0) return;
  const float inv = 1.f / static_cast<float>(2 * radius + 1);
  cv::Mat1f tmp(mask->size());
  for (int pass = 0; pass < 2; ++pass) {
    for (int r = 0; r < mask->rows; ++r) {
      const float* src = mask->ptr<float>(r);
      float* dst = tmp.ptr<float>(r);
      for (int c = 0; c < mask->cols; ++c) {
        float s = 0.f;
        for (int k = std::max(0, c - radius); k <= std::min(mask->cols - 1, c + radius); ++k)
          s += src[k];
        dst[c] = s * inv;
      }
    }
    for (int c = 0; c < mask->cols; ++c) {
      for (int r = 0; r < mask->rows; ++r) {
        float s = 0.f;
        for (int k = std::max(0, r - radius); k <= std::min(mask->rows - 1, r + radius); ++k)
          s += tmp(k, c);
        (*mask)(r, c) = s * inv;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Colours.

Colour Grey(double v) { return Colour(static_cast<float>(v), static_cast<float>(v), static_cast<float>(v)); }

// HSV (hue in degrees, saturation 0..1, value 0..255) to BGR.
Colour Hsv(double hue_deg, double sat, double val) {
  double h = std::fmod(hue_deg, 360.0);
  if (h < 0) h += 360.0;
  h /= 60.0;
  const int i = static_cast<int>(h) % 6;
  const double f = h - std::floor(h);
  const double p = val * (1 - sat), q = val * (1 - sat * f), t = val * (1 - sat * (1 - f));
  double r = val, g = t, b = p;
  switch (i) {
    case 0: r = val; g = t; b = p; break;
    case 1: r = q; g = val; b = p; break;
    case 2: r = p; g = val; b = t; break;
    case 3: r = p; g = q; b = val; break;
    case 4: r = t; g = p; b = val; break;
    default: r = val; g = p; b = q; break;
  }
  return Colour(static_cast<float>(b), static_cast<float>(g), static_cast<float>(r));
}

// A random colour of random hue with saturation and value drawn from the given ranges.
Colour RandomColour(Rng& rng, double sat_lo, double sat_hi, double val_lo, double val_hi) {
  const double hue = rng.Uniform(0.0, 360.0);
  const double sat = rng.Uniform(sat_lo, sat_hi);
  const double val = rng.Uniform(val_lo, val_hi);
  return Hsv(hue, sat, val);
}

Colour Scale(const Colour& c, double k) { return c * static_cast<float>(k); }
cv::Scalar S(const Colour& c) { return cv::Scalar(c[0], c[1], c[2]); }

// ---------------------------------------------------------------------------------------------
// Canvas: the float image plus the metre <-> texel conversion.

struct Canvas {
  cv::Mat3f img;
  double ppm = 1.0;        // texels per metre
  double height_m = 0.0;   // surface height (metres)
  bool y_up = false;       // true: y is the height above the bottom edge (walls);
                           // false: y grows with the row index (floor, ceiling)

  int X(double x_m) const { return static_cast<int>(std::lround(x_m * ppm)); }
  int Y(double y_m) const {
    return static_cast<int>(std::lround((y_up ? height_m - y_m : y_m) * ppm));
  }
  cv::Point P(double x_m, double y_m) const { return cv::Point(X(x_m), Y(y_m)); }
  // A length in texels, at least min_px.
  int L(double len_m, int min_px = 1) const {
    return std::max(min_px, static_cast<int>(std::lround(len_m * ppm)));
  }
  // Texels of [x, x + w] x [y, y + h] (y is the bottom edge when y_up, the top edge otherwise);
  // at least one texel each way.
  cv::Rect R(double x, double y, double w, double h) const {
    const int c0 = X(x), c1 = X(x + w);
    const int r0 = y_up ? Y(y + h) : Y(y);
    const int r1 = y_up ? Y(y) : Y(y + h);
    return cv::Rect(c0, r0, std::max(1, c1 - c0), std::max(1, r1 - r0));
  }
  cv::Rect Clip(const cv::Rect& r) const { return r & cv::Rect(0, 0, img.cols, img.rows); }
};

void Fill(Canvas& cv, const cv::Rect& r, const Colour& c) {
  const cv::Rect k = cv.Clip(r);
  if (!k.empty()) cv.img(k).setTo(S(c));
}

// Adds `delta` to every texel of r.
void Shift(Canvas& cv, const cv::Rect& r, const Colour& delta) {
  const cv::Rect k = cv.Clip(r);
  if (!k.empty()) cv.img(k) += S(delta);
}

// Fills r with a linear gradient from c0 to c1 (top to bottom, or left to right).
void FillGradient(Canvas& cv, const cv::Rect& r, const Colour& c0, const Colour& c1,
                  bool vertical) {
  const cv::Rect k = cv.Clip(r);
  const int n = vertical ? r.height : r.width;
  for (int y = k.y; y < k.br().y; ++y) {
    cv::Vec3f* row = cv.img.ptr<cv::Vec3f>(y);
    for (int x = k.x; x < k.br().x; ++x) {
      const float t = ((vertical ? y - r.y : x - r.x) + 0.5f) / static_cast<float>(n);
      row[x] = c0 + (c1 - c0) * t;
    }
  }
}

// Adds value noise (and optionally grain) to r, the same amount to each channel times `weight`.
void AddNoise(Canvas& cv, const cv::Rect& r, uint64_t seed, double cell_x_px, double cell_y_px,
              float amplitude, float grain = 0.f) {
  const cv::Rect k = cv.Clip(r);
  if (k.empty()) return;
  cv::Mat1f f = cv::Mat1f::zeros(k.size());
  AddValueNoise(&f, k.tl(), seed, cell_x_px, cell_y_px, amplitude);
  AddGrain(&f, k.tl(), Mix64(seed ^ 0x5151), grain);
  for (int y = 0; y < k.height; ++y) {
    cv::Vec3f* row = cv.img.ptr<cv::Vec3f>(k.y + y);
    const float* fr = f.ptr<float>(y);
    for (int x = 0; x < k.width; ++x) row[k.x + x] += Colour(fr[x], fr[x], fr[x]);
  }
}

// Blends `colour` over the canvas with weight alpha * mask, mask (values 0..1) placed with its
// (0, 0) at texel tl.
void Composite(Canvas& cv, cv::Point tl, const cv::Mat1f& mask, const Colour& colour,
               float alpha) {
  const cv::Rect k = cv.Clip(cv::Rect(tl, mask.size()));
  for (int y = k.y; y < k.br().y; ++y) {
    cv::Vec3f* row = cv.img.ptr<cv::Vec3f>(y);
    const float* m = mask.ptr<float>(y - tl.y);
    for (int x = k.x; x < k.br().x; ++x) {
      const float a = alpha * m[x - tl.x];
      row[x] += (colour - row[x]) * a;
    }
  }
}

// A soft shadow of rectangle r, offset by (dx, dy) texels and blurred by `radius` texels.
void SoftShadow(Canvas& cv, const cv::Rect& r, int dx, int dy, int radius, float alpha) {
  const int pad = 2 * radius + 1;
  if (static_cast<double>(r.width + 2 * pad) * (r.height + 2 * pad) > 4.0e6) return;
  cv::Mat1f mask = cv::Mat1f::zeros(r.height + 2 * pad, r.width + 2 * pad);
  mask(cv::Rect(pad, pad, r.width, r.height)).setTo(1.f);
  SoftenMask(&mask, radius);
  Composite(cv, cv::Point(r.x - pad + dx, r.y - pad + dy), mask, Colour(0, 0, 0), alpha);
}

// A soft-edged ellipse blended over the canvas (stains, wear, dirt).
void SoftBlob(Canvas& cv, cv::Point centre, cv::Size axes, double angle_deg, const Colour& colour,
              float alpha, int radius) {
  const int half = std::max(axes.width, axes.height) + 2 * radius + 1;
  if (half > 2000) return;
  cv::Mat1f mask = cv::Mat1f::zeros(2 * half + 1, 2 * half + 1);
  cv::ellipse(mask, cv::Point(half, half), axes, angle_deg, 0, 360, cv::Scalar(1.0), cv::FILLED);
  SoftenMask(&mask, radius);
  Composite(cv, cv::Point(centre.x - half, centre.y - half), mask, colour, alpha);
}

// Lighter top and left edges, darker bottom and right edges of r (a raised edge seen with light
// from above); negative deltas give a recess.
void Bevel(Canvas& cv, const cv::Rect& r, int t, float light, float dark) {
  t = std::max(1, std::min(t, std::min(r.width, r.height) / 2));
  Shift(cv, cv::Rect(r.x, r.y, r.width, t), Grey(light));
  Shift(cv, cv::Rect(r.x, r.y + t, t, r.height - t), Grey(0.6 * light));
  Shift(cv, cv::Rect(r.x, r.br().y - t, r.width, t), Grey(-dark));
  Shift(cv, cv::Rect(r.br().x - t, r.y, t, r.height - t), Grey(-0.6 * dark));
}

// ---------------------------------------------------------------------------------------------
// Doors.

// The look shared by the doors of one wall; every door varies it.
struct DoorScheme {
  bool wood = true;
  Colour leaf;   // leaf colour
  Colour frame;  // frame colour
  double frame_w_m = 0.06;
};

DoorScheme RandomDoorScheme(Rng& rng, bool plain) {
  DoorScheme s;
  s.wood = !plain && rng.Chance(0.55);
  if (s.wood) {
    const double v = rng.Uniform(0.75, 1.2);
    s.leaf = Scale(Colour(70, 112, 160), v);
  } else {
    const double hue = rng.Uniform(0.0, 360.0);
    const double sat = rng.Uniform(0.05, plain ? 0.12 : 0.35);
    const double val = rng.Uniform(plain ? 150.0 : 110.0, plain ? 185.0 : 215.0);
    s.leaf = Hsv(hue, sat, val);
  }
  const double frame_val = rng.Uniform(0.0, 1.0);
  if (frame_val < 0.5) {
    s.frame = Grey(rng.Uniform(205.0, 235.0));
  } else if (frame_val < 0.8 || plain) {
    s.frame = Grey(rng.Uniform(110.0, 160.0));
  } else {
    s.frame = Scale(s.leaf, 0.8);
  }
  s.frame_w_m = rng.Uniform(0.045, 0.08);
  return s;
}

// A metal lever handle with its back plate and lock cylinder; `toward` = +1 points the lever
// right, -1 left.
void DrawHandle(Canvas& cv, double x_m, double y_m, int toward, Rng& rng) {
  const Colour metal = Grey(rng.Uniform(150.0, 215.0));
  const double plate_h = rng.Uniform(0.14, 0.22);
  const double plate_w = rng.Uniform(0.028, 0.045);
  const cv::Rect plate = cv.R(x_m - plate_w / 2, y_m - plate_h * 0.65, plate_w, plate_h);
  SoftShadow(cv, plate, cv.L(0.004), cv.L(0.008), cv.L(0.005), 0.35f);
  Fill(cv, plate, metal);
  Bevel(cv, plate, cv.L(0.003), 25.f, 35.f);
  const double lever_len = rng.Uniform(0.1, 0.14);
  const double lever_t = rng.Uniform(0.016, 0.024);
  const cv::Rect lever = toward > 0 ? cv.R(x_m, y_m - lever_t / 2, lever_len, lever_t)
                                    : cv.R(x_m - lever_len, y_m - lever_t / 2, lever_len, lever_t);
  SoftShadow(cv, lever, cv.L(0.004), cv.L(0.01), cv.L(0.006), 0.4f);
  FillGradient(cv, lever, Scale(metal, 1.15), Scale(metal, 0.7), true);
  // Lock cylinder below the lever.
  cv::circle(cv.img, cv.P(x_m, y_m - plate_h * 0.45), cv.L(0.009), S(Scale(metal, 0.5)),
             cv::FILLED);
}

// One door in the wall, leaf from x_m to x_m + width_m, frame around it; `rich` adds panels,
// glass, kick plates, signs, closers and hinges.
void DrawDoor(Canvas& cv, double x_m, double width_m, double height_m, const DoorScheme& scheme,
              Rng& rng, bool rich) {
  const double fw = scheme.frame_w_m;
  const double shade = rng.Uniform(0.9, 1.1);
  const Colour leaf = Scale(scheme.leaf, shade);
  const Colour frame = Scale(scheme.frame, rng.Uniform(0.96, 1.04));
  const cv::Rect frame_r = cv.R(x_m - fw, 0.0, width_m + 2 * fw, height_m + fw);
  SoftShadow(cv, frame_r, cv.L(0.005), cv.L(0.01), cv.L(0.012), 0.25f);
  Fill(cv, frame_r, frame);
  Bevel(cv, frame_r, cv.L(0.01), 14.f, 20.f);
  AddNoise(cv, frame_r, rng.Fork(), cv.ppm * 0.05, cv.ppm * 0.05, 4.f);
  // The leaf, a gap under it and a shadow line along the frame's inner edge.
  const cv::Rect leaf_r = cv.R(x_m, 0.008, width_m, height_m - 0.008);
  Fill(cv, cv.R(x_m, 0.0, width_m, height_m), Grey(25));
  Fill(cv, leaf_r, leaf);
  if (scheme.wood) {
    // Wood grain: value noise stretched along the leaf's height.
    AddNoise(cv, leaf_r, rng.Fork(), cv.ppm * 0.006, cv.ppm * 0.5, 9.f);
    AddNoise(cv, leaf_r, rng.Fork(), cv.ppm * 0.035, cv.ppm * 1.2, 10.f);
  } else {
    AddNoise(cv, leaf_r, rng.Fork(), cv.ppm * 0.15, cv.ppm * 0.15, 5.f);
  }
  Shift(cv, cv::Rect(leaf_r.x, leaf_r.y, leaf_r.width, cv.L(0.006)), Grey(-35));
  const bool hinge_left = rng.Chance(0.5);
  const double handle_x = hinge_left ? x_m + width_m - 0.07 : x_m + 0.07;
  if (rich) {
    // Panels: 0 flush, 1 vision slot, 2 upper glass, 3 two panels, 4 four panels.
    const int style = rng.Int(0, 4);
    const double m = rng.Uniform(0.1, 0.16);  // panel margin
    const int bev = cv.L(0.012);
    if (style == 1) {
      const double gw = rng.Uniform(0.1, 0.2);
      const double gx = hinge_left ? x_m + width_m - 0.25 - gw : x_m + 0.25;
      const double gy = rng.Uniform(1.1, 1.3);
      const double gh = rng.Uniform(0.5, 0.75);
      const cv::Rect g = cv.R(gx, gy, gw, gh);
      FillGradient(cv, g, Colour(95, 85, 70), Colour(55, 48, 42), false);
      Bevel(cv, g, bev, -25.f, -15.f);
    } else if (style == 2) {
      const cv::Rect g = cv.R(x_m + m, height_m * 0.5, width_m - 2 * m, height_m * 0.5 - m);
      FillGradient(cv, g, Colour(110, 100, 88), Colour(60, 55, 50), true);
      // A few diagonal reflections.
      const int n = rng.Int(1, 3);
      for (int i = 0; i < n; ++i) {
        const double u = rng.Uniform(0.0, 1.0);
        const double w = rng.Uniform(0.02, 0.08);
        const int x0 = g.x + static_cast<int>(u * g.width);
        std::vector<cv::Point> poly = {{x0, g.y + g.height}, {x0 + cv.L(w), g.y + g.height},
                                       {x0 + cv.L(w) + g.height / 2, g.y},
                                       {x0 + g.height / 2, g.y}};
        cv::Mat3f roi = cv.img(cv.Clip(g));
        cv::Mat3f tmp = roi.clone();
        for (auto& p : poly) p -= cv.Clip(g).tl();
        cv::fillConvexPoly(tmp, poly, cv::Scalar(150, 145, 140));
        cv::addWeighted(roi, 0.8, tmp, 0.2, 0.0, roi);
      }
      Bevel(cv, g, bev, -25.f, -15.f);
      const cv::Rect lower = cv.R(x_m + m, m + 0.1, width_m - 2 * m, height_m * 0.5 - 2 * m - 0.1);
      Bevel(cv, lower, bev, -18.f, -14.f);
    } else if (style >= 3) {
      const int cols = style == 4 ? 2 : 1;
      const double split = rng.Uniform(0.42, 0.6) * height_m;
      const double pw = (width_m - (cols + 1) * m) / cols;
      for (int c = 0; c < cols; ++c) {
        const double px = x_m + m + c * (pw + m);
        Bevel(cv, cv.R(px, m + 0.1, pw, split - m - 0.1 - m / 2), bev, -18.f, -14.f);
        Bevel(cv, cv.R(px, split + m / 2, pw, height_m - split - 1.5 * m), bev, -18.f, -14.f);
      }
    }
    // Kick plate.
    if (rng.Chance(0.4)) {
      const cv::Rect k = cv.R(x_m + 0.02, 0.02, width_m - 0.04, rng.Uniform(0.15, 0.3));
      Fill(cv, k, Grey(rng.Uniform(165.0, 200.0)));
      AddNoise(cv, k, rng.Fork(), cv.ppm * 0.4, 1.0, 8.f, 3.f);
      Bevel(cv, k, cv.L(0.003), 20.f, 25.f);
    }
    // Closer at the top of the hinge side.
    if (rng.Chance(0.35)) {
      const double cw = rng.Uniform(0.25, 0.35);
      const double cx = hinge_left ? x_m + 0.05 : x_m + width_m - 0.05 - cw;
      const cv::Rect c = cv.R(cx, height_m - 0.12, cw, 0.055);
      SoftShadow(cv, c, cv.L(0.005), cv.L(0.01), cv.L(0.008), 0.4f);
      Fill(cv, c, Grey(rng.Uniform(60.0, 190.0)));
      Bevel(cv, c, cv.L(0.006), 25.f, 30.f);
    }
    // Hinges on the hinge side.
    const double hx = hinge_left ? x_m - 0.006 : x_m + width_m - 0.006;
    for (double hy : {0.25, height_m * 0.5, height_m - 0.3})
      Fill(cv, cv.R(hx, hy, 0.012, 0.1), Grey(rng.Uniform(90.0, 170.0)));
  }
  DrawHandle(cv, handle_x, rng.Uniform(1.0, 1.07), hinge_left ? -1 : 1, rng);
}

// ---------------------------------------------------------------------------------------------
// Finishing.

// The "light" field added to every channel at the end: low-frequency shading (fractal value
// noise, biggest cell `shade_cell_m`), a fine plaster texture of a few texels and per-texel grain.
cv::Mat1f LightField(const Canvas& cv, uint64_t seed, double shade_cell_m, float shading,
                     float grain) {
  cv::Mat1f light = cv::Mat1f::zeros(cv.img.size());
  AddFbm(&light, cv::Point(0, 0), DeriveSeed(seed, 1), shade_cell_m * cv.ppm, 4, shading);
  AddValueNoise(&light, cv::Point(0, 0), DeriveSeed(seed, 2), 2.5, 2.5, 0.5f * grain);
  AddGrain(&light, cv::Point(0, 0), DeriveSeed(seed, 3), grain);
  return light;
}

// The painted canvas plus `light` (the same on each channel) rounded to 8-bit BGR; without tint
// every texel becomes its luminance on all three channels.
cv::Mat Finish(const Canvas& cv, const cv::Mat1f& light, bool tinted) {
  cv::Mat out(cv.img.size(), CV_8UC3);
  for (int r = 0; r < out.rows; ++r) {
    const cv::Vec3f* src = cv.img.ptr<cv::Vec3f>(r);
    const float* l = light.ptr<float>(r);
    cv::Vec3b* dst = out.ptr<cv::Vec3b>(r);
    for (int c = 0; c < out.cols; ++c) {
      cv::Vec3f v = src[c] + Colour(l[c], l[c], l[c]);
      if (!tinted) {
        const float g = 0.114f * v[0] + 0.587f * v[1] + 0.299f * v[2];
        v = Colour(g, g, g);
      }
      for (int k = 0; k < 3; ++k) dst[c][k] = cv::saturate_cast<uchar>(v[k]);
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Walls.

// Fills the wall between two door frames (or a frame and a wall end), [a_m, b_m], with posters,
// notice boards, pictures, radiators and the like.
void FillWallSegment(Canvas& cv, double a_m, double b_m, double density, Rng& rng);

// Stains, nail holes, pencil marks and scuffs on the plaster, `density` per the options.
void DrawWallMarks(Canvas& cv, double width_m, double density, Rng& rng) {
  const double area = width_m * cv.height_m;
  // Large faint stains.
  const int stains = static_cast<int>(std::lround(0.6 * area * density));
  for (int i = 0; i < stains; ++i) {
    const double x = rng.Uniform(0.0, width_m);
    const double y = rng.Uniform(0.0, cv.height_m);
    const double rx = rng.Uniform(0.02, 0.15);
    const double ry = rng.Uniform(0.02, 0.15);
    const double ang = rng.Uniform(0.0, 180.0);
    const double tone = rng.Uniform(-40.0, 10.0);
    const float alpha = static_cast<float>(rng.Uniform(0.08, 0.25));
    SoftBlob(cv, cv.P(x, y), cv::Size(cv.L(rx), cv.L(ry)), ang,
             Colour(static_cast<float>(140 + tone), static_cast<float>(160 + tone),
                    static_cast<float>(170 + tone)),
             alpha, cv.L(0.015));
  }
  // Nail holes, dots and blu-tack marks.
  const int dots = static_cast<int>(std::lround(4.0 * area * density));
  for (int i = 0; i < dots; ++i) {
    const double x = rng.Uniform(0.0, width_m);
    const double y = rng.Uniform(0.3, cv.height_m);
    const double r = rng.Uniform(0.0015, 0.006);
    const double v = rng.Uniform(40.0, 140.0);
    cv::circle(cv.img, cv.P(x, y), cv.L(r), S(Grey(v)), cv::FILLED);
  }
  // Pencil and pen strokes.
  const int strokes = static_cast<int>(std::lround(1.0 * area * density));
  for (int i = 0; i < strokes; ++i) {
    const double x = rng.Uniform(0.0, width_m);
    const double y = rng.Uniform(0.5, 1.9);
    const double len = rng.Uniform(0.02, 0.12);
    const double ang = rng.Uniform(0.0, 2 * M_PI);
    const double v = rng.Uniform(60.0, 130.0);
    cv::line(cv.img, cv.P(x, y), cv.P(x + len * std::cos(ang), y + len * std::sin(ang)),
             S(Grey(v)), 1, cv::LINE_8);
  }
  // Scuffs near the floor: short dark strokes from chairs, trolleys and shoes.
  const int scuffs = static_cast<int>(std::lround(2.5 * width_m * density));
  for (int i = 0; i < scuffs; ++i) {
    const double x = rng.Uniform(0.0, width_m);
    const double y = rng.Uniform(0.02, 0.7);
    const double len = rng.Uniform(0.03, 0.3);
    const double ang = rng.Uniform(-0.3, 0.3);
    const double v = rng.Uniform(30.0, 110.0);
    const int t = rng.Int(1, 3);
    const float alpha = static_cast<float>(rng.Uniform(0.25, 0.7));
    const cv::Point p0 = cv.P(x, y);
    const cv::Point p1 = cv.P(x + len * std::cos(ang), y + len * std::sin(ang));
    const cv::Rect box = cv::boundingRect(std::vector<cv::Point>{p0, p1}) + cv::Size(1, 1);
    const int pad = t + 2;
    cv::Mat1f mask = cv::Mat1f::zeros(box.height + 2 * pad, box.width + 2 * pad);
    const cv::Point o(box.x - pad, box.y - pad);
    cv::line(mask, p0 - o, p1 - o, cv::Scalar(1.0), t, cv::LINE_AA);
    Composite(cv, o, mask, Grey(v), alpha);
  }
}

void DrawSkirting(Canvas& cv, double width_m, double height_m, const Colour& colour, Rng& rng,
                  bool rich) {
  if (height_m <= 0.0) return;
  const cv::Rect r = cv.R(0.0, 0.0, width_m, height_m);
  // A faint shadow on the plaster just above it.
  SoftShadow(cv, r, 0, -cv.L(0.002), cv.L(0.004), 0.25f);
  Fill(cv, r, colour);
  AddNoise(cv, r, rng.Fork(), cv.ppm * 0.3, cv.ppm * 0.05, rich ? 6.f : 2.f, rich ? 4.f : 1.f);
  // The rounded top edge catches the light.
  Shift(cv, cv::Rect(r.x, r.y, r.width, cv.L(0.004)), Grey(rich ? 35 : 20));
  if (!rich) return;
  const int marks = static_cast<int>(std::lround(3.0 * width_m));
  for (int i = 0; i < marks; ++i) {
    const double x = rng.Uniform(0.0, width_m);
    const double y = rng.Uniform(0.005, height_m * 0.9);
    const double len = rng.Uniform(0.02, 0.15);
    const double v = rng.Uniform(-30.0, 40.0);
    cv::line(cv.img, cv.P(x, y), cv.P(x + len, y + rng.Uniform(-0.01, 0.01)),
             S(colour + Grey(v)), 1, cv::LINE_8);
  }
}

// A wall of width_m x cv.height_m: plaster, marks, skirting, doors and, between the doors,
// the objects of FillWallSegment (rich) or nothing (plain).
void PaintWall(Canvas& cv, double width_m, uint64_t seed, const TextureOptions& o, bool plain) {
  Rng rng(DeriveSeed(seed, 11));
  const double hue = rng.Uniform(20.0, 220.0);
  const double sat = rng.Uniform(0.02, plain ? 0.06 : 0.12);
  const double val = rng.Uniform(plain ? 185.0 : 175.0, 212.0);
  cv.img.setTo(S(Hsv(hue, sat, val)));
  const double density = plain ? 0.0 : o.detail_density;
  Rng marks_rng(rng.Fork());
  if (density > 0.0) DrawWallMarks(cv, width_m, density, marks_rng);
  Rng skirting_rng(rng.Fork());
  Colour skirting = Grey(plain ? skirting_rng.Uniform(95.0, 130.0) : skirting_rng.Uniform(50.0, 95.0));
  if (!plain && skirting_rng.Chance(0.35)) skirting = Scale(Colour(55, 80, 115), skirting_rng.Uniform(0.7, 1.2));
  DrawSkirting(cv, width_m, o.skirting_height_m, skirting, skirting_rng, !plain);

  // Doors: random gaps between frames (rich), or a mean spacing +-15 % (plain).
  Rng door_rng(rng.Fork());
  const DoorScheme scheme = RandomDoorScheme(door_rng, plain);
  const double fw = scheme.frame_w_m;
  const double door_h = std::min(door_rng.Uniform(2.0, 2.1), cv.height_m - fw - 0.12);
  std::vector<std::pair<double, double>> frames;  // [left, right] of each frame (metres)
  if (door_h > 1.2) {
    if (plain) {
      double centre = door_rng.Uniform(0.2, 1.0) * o.plain_door_spacing_m;
      while (true) {
        const double dw = door_rng.Uniform(0.85, 0.95);
        const double left = centre - dw / 2 - fw;
        if (left >= 0.05 && left + dw + 2 * fw <= width_m - 0.05) frames.push_back({left, left + dw + 2 * fw});
        if (centre > width_m) break;
        const double step = door_rng.Uniform(0.85, 1.15) * o.plain_door_spacing_m;
        centre += step;
      }
    } else {
      double left = door_rng.Uniform(0.15, std::max(0.2, o.door_gap_max_m));
      while (true) {
        const double dw = door_rng.Uniform(0.82, 0.98);
        if (left + dw + 2 * fw > width_m - 0.1) break;
        frames.push_back({left, left + dw + 2 * fw});
        const double gap = door_rng.Uniform(o.door_gap_min_m, o.door_gap_max_m);
        left += dw + 2 * fw + gap;
      }
    }
  }
  for (const auto& f : frames) {
    Rng one(door_rng.Fork());
    DrawDoor(cv, f.first + fw, f.second - f.first - 2 * fw, door_h, scheme, one, !plain);
  }
  if (density <= 0.0) return;
  // Objects between the doors.
  double a = 0.0;
  for (size_t i = 0; i <= frames.size(); ++i) {
    const double b = i < frames.size() ? frames[i].first : width_m;
    Rng seg(rng.Fork());
    FillWallSegment(cv, a, b, density, seg);
    if (i < frames.size()) a = frames[i].second;
  }
}

// Random inner content of a poster or picture: blocks, discs, bars, text-like rows of blobs.
void DrawPosterContent(Canvas& cv, const cv::Rect& r, Rng& rng) {
  const int items = rng.Int(4, 12);
  for (int i = 0; i < items; ++i) {
    const int kind = rng.Int(0, 3);
    const int w = std::max(2, static_cast<int>(r.width * rng.Uniform(0.1, 0.6)));
    const int h = std::max(2, static_cast<int>(r.height * rng.Uniform(0.06, 0.4)));
    const int x = r.x + rng.Int(0, std::max(0, r.width - w));
    const int y = r.y + rng.Int(0, std::max(0, r.height - h));
    const Colour c = RandomColour(rng, 0.0, 0.8, 20.0, 240.0);
    if (kind == 0) {
      Fill(cv, cv::Rect(x, y, w, h), c);
    } else if (kind == 1) {
      const int rad = std::max(2, std::min(w, h) / 2);
      cv::circle(cv.img, cv::Point(x + w / 2, y + h / 2), rad, S(c), cv::FILLED);
    } else if (kind == 2) {
      const Colour c1 = RandomColour(rng, 0.0, 0.6, 30.0, 230.0);
      const bool vertical = rng.Chance(0.5);
      FillGradient(cv, cv::Rect(x, y, w, h), c, c1, vertical);
    } else {
      // Text-like rows: short dark dashes of random lengths.
      const int line_h = std::max(2, cv.L(0.012));
      for (int yy = y; yy + line_h < y + h; yy += 2 * line_h) {
        int xx = x;
        while (xx < x + w) {
          const int len = std::max(2, static_cast<int>(line_h * rng.Uniform(1.0, 5.0)));
          Fill(cv, cv::Rect(xx, yy, std::min(len, x + w - xx), line_h), Grey(rng.Uniform(10.0, 70.0)));
          xx += len + std::max(1, static_cast<int>(line_h * rng.Uniform(0.6, 1.6)));
        }
      }
    }
  }
}

void FillWallSegment(Canvas& cv, double a_m, double b_m, double density, Rng& rng) {
  // Walk along the segment placing objects at random gaps; kinds and sizes vary so that every
  // object's corners look different from its neighbours'.
  double x = a_m + rng.Uniform(0.1, 0.5);
  while (x < b_m - 0.2) {
    const int kind = rng.Int(0, 11);
    double w = 0.0;
    if (kind <= 3 || kind >= 10) {  // poster / notice board / framed picture
      w = rng.Uniform(0.35, 1.2);
      const double h = rng.Uniform(0.3, 0.9);
      const double y = rng.Uniform(0.9, std::max(0.95, cv.height_m - 0.35 - h));
      if (x + w > b_m - 0.05) break;
      const cv::Rect r = cv.R(x, y, w, h);
      SoftShadow(cv, r, cv.L(0.01), cv.L(0.01), cv.L(0.01), 0.25f);
      const int frame = kind == 2 || kind == 10 ? cv.L(0.03) : 0;  // framed picture
      if (frame > 0) Fill(cv, r, RandomColour(rng, 0.1, 0.5, 30.0, 120.0));
      const cv::Rect inner(r.x + frame, r.y + frame, std::max(1, r.width - 2 * frame),
                           std::max(1, r.height - 2 * frame));
      Fill(cv, inner, kind == 3 ? Colour(60, 110, 150) : RandomColour(rng, 0.0, 0.5, 150.0, 250.0));
      if (kind == 3) {  // cork board with pinned sheets
        const int sheets = rng.Int(3, 9);
        for (int k = 0; k < sheets; ++k) {
          const int sw = std::max(3, static_cast<int>(inner.width * rng.Uniform(0.15, 0.4)));
          const int sh = std::max(3, static_cast<int>(inner.height * rng.Uniform(0.2, 0.5)));
          const int sx = inner.x + rng.Int(0, std::max(0, inner.width - sw));
        const int sy = inner.y + rng.Int(0, std::max(0, inner.height - sh));
        const cv::Rect sr(sx, sy, sw, sh);
          Fill(cv, sr, RandomColour(rng, 0.0, 0.3, 200.0, 250.0));
          DrawPosterContent(cv, cv::Rect(sr.x + 2, sr.y + 2, std::max(1, sr.width - 4), std::max(1, sr.height - 4)), rng);
        }
      } else {
        DrawPosterContent(cv, inner, rng);
      }
    } else if (kind == 4) {  // light switch / socket pair
      w = rng.Uniform(0.08, 0.2);
      const double y = rng.Chance(0.5) ? rng.Uniform(1.0, 1.2) : rng.Uniform(0.25, 0.4);
      const cv::Rect r = cv.R(x, y, w, 0.09);
      Fill(cv, r, Grey(rng.Uniform(215.0, 245.0)));
      Bevel(cv, r, 1, 15.f, -25.f);
      Fill(cv, cv::Rect(r.x + r.width / 3, r.y + r.height / 3, std::max(1, r.width / 6), std::max(1, r.height / 3)), Grey(120));
    } else if (kind == 5) {  // radiator: vertical fins
      w = rng.Uniform(0.6, 1.4);
      if (x + w > b_m - 0.05) break;
      const double h = rng.Uniform(0.4, 0.6);
      const cv::Rect r = cv.R(x, rng.Uniform(0.15, 0.25), w, h);
      Fill(cv, r, Grey(rng.Uniform(200.0, 235.0)));
      const int fin = std::max(2, cv.L(rng.Uniform(0.04, 0.07)));
      for (int fx = r.x + fin / 2; fx < r.br().x; fx += fin)
        Fill(cv, cv::Rect(fx, r.y, std::max(1, fin / 4), r.height), Grey(rng.Uniform(140.0, 175.0)));
    } else if (kind == 6) {  // sign: coloured plate with a pictogram
      w = rng.Uniform(0.2, 0.45);
      const double h = rng.Uniform(0.12, 0.3);
      const cv::Rect r = cv.R(x, rng.Uniform(1.6, std::max(1.65, cv.height_m - 0.3 - h)), w, h);
      const Colour c = RandomColour(rng, 0.5, 0.9, 60.0, 180.0);
      Fill(cv, r, c);
      const cv::Point ctr(r.x + r.width / 3, r.y + r.height / 2);
      cv::circle(cv.img, ctr, std::max(2, r.height / 4), S(Grey(245)), cv::FILLED);
      Fill(cv, cv::Rect(r.x + r.width / 2, r.y + r.height / 3, std::max(1, r.width / 3), std::max(1, r.height / 3)), Grey(245));
    } else if (kind == 7) {  // extinguisher / box
      w = rng.Uniform(0.15, 0.35);
      const double h = rng.Uniform(0.3, 0.6);
      const cv::Rect r = cv.R(x, rng.Uniform(0.3, 0.9), w, h);
      Fill(cv, r, RandomColour(rng, 0.6, 0.9, 90.0, 170.0));
      Bevel(cv, r, std::max(1, cv.L(0.01)), 25.f, -35.f);
    } else {  // bare wall
      w = rng.Uniform(0.1, 0.4) / std::max(0.2, density);
    }
    x += w + rng.Uniform(0.05, 0.35) / std::max(0.2, density);
  }
}

// ---------------------------------------------------------------------------------------------
// Floors and ceilings.

// A nearly uniform seamless floor with a very few faint marks.
void PaintPlainFloor(Canvas& cv, uint64_t seed) {
  Rng rng(DeriveSeed(seed, 21));
  const double hue = rng.Uniform(0.0, 360.0);
  const double sat = rng.Uniform(0.02, 0.08);
  const double val = rng.Uniform(120.0, 165.0);
  const Colour base = Hsv(hue, sat, val);
  cv.img.setTo(S(base));
  const double area = cv.img.cols * cv.img.rows / (cv.ppm * cv.ppm);
  const int marks = static_cast<int>(std::lround(0.15 * area));
  for (int i = 0; i < marks; ++i) {
    const double x = rng.Uniform(0.0, cv.img.cols / cv.ppm);
    const double y = rng.Uniform(0.0, cv.img.rows / cv.ppm);
    const double r = rng.Uniform(0.02, 0.08);
    const double tone = rng.Uniform(-25.0, -8.0);
    const float alpha = static_cast<float>(rng.Uniform(0.15, 0.3));
    SoftBlob(cv, cv.P(x, y), cv::Size(cv.L(r), cv.L(r * 0.6)), rng.Uniform(0.0, 180.0),
             base + Grey(tone), alpha, cv.L(0.02));
  }
}

// A nearly uniform plaster ceiling with a light every few metres along its longer side.
void PaintPlainCeiling(Canvas& cv, uint64_t seed) {
  Rng rng(DeriveSeed(seed, 31));
  const double val = rng.Uniform(200.0, 225.0);
  cv.img.setTo(S(Hsv(rng.Uniform(30.0, 60.0), 0.03, val)));
  const double w = cv.img.cols / cv.ppm, h = cv.img.rows / cv.ppm;
  const bool along_x = w >= h;
  const double length = along_x ? w : h, across = along_x ? h : w;
  const double lamp_len = rng.Uniform(0.6, 1.2);
  const double lamp_w = rng.Uniform(0.15, 0.3);
  double s = rng.Uniform(0.5, 2.5);
  while (s + lamp_len < length) {
    const double c = across / 2 + rng.Uniform(-0.1, 0.1);
    const cv::Rect r = along_x ? cv.R(s, c - lamp_w / 2, lamp_len, lamp_w)
                               : cv.R(c - lamp_w / 2, s, lamp_w, lamp_len);
    Fill(cv, r, Grey(228));
    const int b = cv.L(0.02);
    Fill(cv, cv::Rect(r.x + b, r.y + b, std::max(1, r.width - 2 * b), std::max(1, r.height - 2 * b)),
         Grey(254));
    s += lamp_len + rng.Uniform(2.2, 3.8);
  }
}

// Tiles with grout; every tile its own shade, noise and wear, so the grid never repeats.
void PaintFloor(Canvas& cv, uint64_t seed, const TextureOptions& o) {
  Rng rng(DeriveSeed(seed, 41));
  const double base = rng.Uniform(110.0, 170.0);
  const double hue = rng.Uniform(0.0, 360.0);
  cv.img.setTo(S(Grey(base * 0.55)));  // grout
  const double tile = o.floor_tile_m;
  const int grout = std::max(1, cv.L(o.grout_width_m));
  const double w = cv.img.cols / cv.ppm, h = cv.img.rows / cv.ppm;
  int index = 0;
  for (double ty = 0.0; ty < h; ty += tile) {
    for (double tx = 0.0; tx < w; tx += tile, ++index) {
      Rng t(DeriveSeed(seed, 4100 + index));
      const cv::Rect r = cv.R(tx, ty, tile, tile);
      const cv::Rect in(r.x + grout, r.y + grout, std::max(1, r.width - grout), std::max(1, r.height - grout));
      // One draw per statement: argument evaluation order is unspecified in C++.
      const double sat = t.Uniform(0.02, 0.12);
      const double shade = base + t.Uniform(-28.0, 28.0);
      Fill(cv, in, Hsv(hue, sat, shade));
      const uint64_t noise_seed = t.Fork();
      const double cell_x = t.Uniform(0.03, 0.12);
      const double cell_y = t.Uniform(0.03, 0.12);
      const double amp = t.Uniform(6.0, 16.0);
      AddNoise(cv, in, noise_seed, cv.L(cell_x), cv.L(cell_y), static_cast<float>(amp),
               static_cast<float>(o.grain_amplitude));
      const int wear = t.Int(0, 3);
      for (int k = 0; k < wear; ++k) {
        const double cx = tx + t.Uniform(0.0, tile), cy = ty + t.Uniform(0.0, tile);
        const double rx = t.Uniform(0.02, 0.12), ry = t.Uniform(0.01, 0.06);
        const double angle = t.Uniform(0.0, 180.0);
        const double tone = t.Uniform(-50.0, 30.0);
        SoftBlob(cv, cv.P(cx, cy), cv::Size(cv.L(rx), cv.L(ry)), angle, Grey(base + tone), 0.5f, cv.L(0.01));
      }
    }
  }
  // Scuffs and marks across tiles.
  const int marks = static_cast<int>(std::lround(o.detail_density * 3.0 * w * h));
  for (int i = 0; i < marks; ++i) {
    const double mx = rng.Uniform(0.0, w);
    const double my = rng.Uniform(0.0, h);
    const cv::Point a = cv.P(mx, my);
    const double len = rng.Uniform(0.03, 0.2), ang = rng.Uniform(0.0, 2 * M_PI);
    const cv::Point b(a.x + cv.L(len * std::cos(ang), 0), a.y + cv.L(len * std::sin(ang), 0));
    const double tone = rng.Uniform(20.0, 80.0);
    cv::line(cv.img, a, b, S(Grey(tone)), std::max(1, cv.L(0.004)));
  }
}

// Suspended ceiling: panels on a T-bar grid, each panel its own speckle; lights, vents and
// sprinklers in irregular cells.
void PaintCeiling(Canvas& cv, uint64_t seed, const TextureOptions& o) {
  Rng rng(DeriveSeed(seed, 51));
  const double base = rng.Uniform(205.0, 230.0);
  cv.img.setTo(S(Grey(base - 45.0)));  // T-bar grid
  const double panel = o.ceiling_panel_m;
  const int bar = std::max(1, cv.L(o.ceiling_grid_width_m));
  const double w = cv.img.cols / cv.ppm, h = cv.img.rows / cv.ppm;
  const double ox = rng.Uniform(0.0, panel), oy = rng.Uniform(0.0, panel);
  int index = 0;
  for (double py = -oy; py < h; py += panel) {
    for (double px = -ox; px < w; px += panel, ++index) {
      Rng t(DeriveSeed(seed, 5100 + index));
      const cv::Rect r = cv.R(px, py, panel, panel);
      const cv::Rect in(r.x + bar, r.y + bar, std::max(1, r.width - bar), std::max(1, r.height - bar));
      Fill(cv, in, Grey(base + t.Uniform(-12.0, 8.0)));
      const uint64_t noise_seed = t.Fork();
      const double amp = t.Uniform(4.0, 10.0);
      AddNoise(cv, in, noise_seed, cv.L(0.02), cv.L(0.02), static_cast<float>(amp), 6.f);
      const double u = t.Uniform();
      if (u < 0.16) {  // light fixture: bright panel with a frame and louvres
        Fill(cv, in, Grey(252));
        Bevel(cv, in, std::max(1, cv.L(0.02)), -30.f, -50.f);
        const int louvres = t.Int(2, 5);
        for (int k = 1; k < louvres; ++k)
          Fill(cv, cv::Rect(in.x, in.y + k * in.height / louvres, in.width, std::max(1, cv.L(0.008))), Grey(200));
      } else if (u < 0.24) {  // vent: dark slots
        const cv::Rect v(in.x + in.width / 4, in.y + in.height / 4, std::max(2, in.width / 2), std::max(2, in.height / 2));
        Fill(cv, v, Grey(150));
        for (int yy = v.y; yy < v.br().y; yy += std::max(2, cv.L(0.025)))
          Fill(cv, cv::Rect(v.x, yy, v.width, std::max(1, cv.L(0.01))), Grey(70));
      } else if (u < 0.34) {  // sprinkler / smoke detector
        const int cx = in.x + t.Int(0, std::max(0, in.width - 1));
        const int cy = in.y + t.Int(0, std::max(0, in.height - 1));
        const cv::Point c(cx, cy);
        const double radius = t.Uniform(0.02, 0.05);
        const double tone = t.Uniform(90.0, 250.0);
        cv::circle(cv.img, c, std::max(2, cv.L(radius)), S(Grey(tone)), cv::FILLED);
      }
    }
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Public API.

bool ParseTextureKind(const std::string& name, TextureKind* kind) {
  static const struct {
    const char* name;
    TextureKind kind;
  } kKinds[] = {{"wall", TextureKind::kWall},           {"floor", TextureKind::kFloor},
                {"ceiling", TextureKind::kCeiling},     {"plainwall", TextureKind::kPlainWall},
                {"plainfloor", TextureKind::kPlainFloor}, {"plainceiling", TextureKind::kPlainCeiling}};
  for (const auto& k : kKinds) {
    if (name == k.name) {
      *kind = k.kind;
      return true;
    }
  }
  return false;
}

const char* TextureKindName(TextureKind kind) {
  switch (kind) {
    case TextureKind::kWall: return "wall";
    case TextureKind::kFloor: return "floor";
    case TextureKind::kCeiling: return "ceiling";
    case TextureKind::kPlainWall: return "plainwall";
    case TextureKind::kPlainFloor: return "plainfloor";
    case TextureKind::kPlainCeiling: return "plainceiling";
  }
  return "unknown";
}

bool IsPlainTexture(TextureKind kind) {
  return kind == TextureKind::kPlainWall || kind == TextureKind::kPlainFloor ||
         kind == TextureKind::kPlainCeiling;
}

bool TextureOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& msg) {
    if (error) *error = "TextureOptions: " + msg;
    return false;
  };
  const struct {
    const char* name;
    double value;
    double min;
    bool strict;  // value must be > min (else >= min)
  } kFields[] = {{"px_per_m", px_per_m, 0.0, true},
                 {"grain_amplitude", grain_amplitude, 0.0, false},
                 {"shading_amplitude", shading_amplitude, 0.0, false},
                 {"detail_density", detail_density, 0.0, false},
                 {"door_gap_min_m", door_gap_min_m, 0.0, true},
                 {"door_gap_max_m", door_gap_max_m, door_gap_min_m, false},
                 {"plain_door_spacing_m", plain_door_spacing_m, 0.0, true},
                 {"skirting_height_m", skirting_height_m, 0.0, false},
                 {"grout_width_m", grout_width_m, 0.0, false},
                 {"floor_tile_m", floor_tile_m, grout_width_m, true},
                 {"ceiling_grid_width_m", ceiling_grid_width_m, 0.0, false},
                 {"ceiling_panel_m", ceiling_panel_m, ceiling_grid_width_m, true},
                 {"plain_shading_amplitude", plain_shading_amplitude, 0.0, false},
                 {"plain_grain_amplitude", plain_grain_amplitude, 0.0, false}};
  for (const auto& f : kFields) {
    if (!std::isfinite(f.value)) return fail(std::string(f.name) + " must be finite");
    if (f.strict ? !(f.value > f.min) : !(f.value >= f.min)) {
      return fail(std::string(f.name) + " = " + std::to_string(f.value) + " must be " +
                  (f.strict ? "> " : ">= ") + std::to_string(f.min));
    }
  }
  return true;
}

cv::Size TextureSizePx(double width_m, double height_m, const TextureOptions& options) {
  // Sides that are not finite or far beyond kMaxTextureSidePx come back as 0 (never a valid size).
  auto side = [&](double len_m) {
    const double px = std::round(len_m * options.px_per_m);
    return std::isfinite(px) && px >= 0.0 && px <= 4.0 * kMaxTextureSidePx ? static_cast<int>(px) : 0;
  };
  return cv::Size(side(width_m), side(height_m));
}

cv::Mat GenerateTexture(TextureKind kind, double width_m, double height_m, uint64_t seed,
                        const TextureOptions& options) {
  if (!options.IsValid(nullptr) || !std::isfinite(width_m) || !std::isfinite(height_m)) {
    return cv::Mat();
  }
  const cv::Size size = TextureSizePx(width_m, height_m, options);
  if (size.width < 1 || size.height < 1 || size.width > kMaxTextureSidePx ||
      size.height > kMaxTextureSidePx) {
    return cv::Mat();
  }
  Canvas cv;
  cv.img = cv::Mat3f(size);
  cv.ppm = options.px_per_m;
  cv.height_m = size.height / options.px_per_m;
  const bool plain = IsPlainTexture(kind);
  const float shading =
      static_cast<float>(plain ? options.plain_shading_amplitude : options.shading_amplitude);
  const float grain =
      static_cast<float>(plain ? options.plain_grain_amplitude : options.grain_amplitude);
  double shade_cell_m = 1.5;
  switch (kind) {
    case TextureKind::kWall:
    case TextureKind::kPlainWall:
      cv.y_up = true;
      PaintWall(cv, size.width / options.px_per_m, seed, options, plain);
      shade_cell_m = plain ? 3.0 : 1.5;
      break;
    case TextureKind::kFloor:
      PaintFloor(cv, seed, options);
      shade_cell_m = 2.0;
      break;
    case TextureKind::kPlainFloor:
      PaintPlainFloor(cv, seed);
      shade_cell_m = 3.0;
      break;
    case TextureKind::kCeiling:
      PaintCeiling(cv, seed, options);
      shade_cell_m = 2.0;
      break;
    case TextureKind::kPlainCeiling:
      PaintPlainCeiling(cv, seed);
      shade_cell_m = 3.0;
      break;
  }
  return Finish(cv, LightField(cv, DeriveSeed(seed, 99), shade_cell_m, shading, grain),
                options.tinted);
}

}  // namespace sim
