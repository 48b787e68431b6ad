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
#include <opencv2/imgproc.hpp>
#include <vector>

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
// sigma ~ 0.8 radius), zero outside; running sums in a fixed order.
void SoftenMask(cv::Mat1f* mask, int radius) {
  if (radius <= 0 || mask->empty()) return;
  const float inv = 1.f / static_cast<float>(2 * radius + 1);
  const int rows = mask->rows, cols = mask->cols;
  std::vector<double> line(std::max(rows, cols));
  for (int pass = 0; pass < 2; ++pass) {
    for (int r = 0; r < rows; ++r) {
      float* p = mask->ptr<float>(r);
      std::copy(p, p + cols, line.begin());
      double s = 0.0;
      for (int k = 0; k <= std::min(cols - 1, radius); ++k) s += line[k];
      for (int c = 0; c < cols; ++c) {
        p[c] = static_cast<float>(s) * inv;
        if (c + radius + 1 < cols) s += line[c + radius + 1];
        if (c - radius >= 0) s -= line[c - radius];
      }
    }
    for (int c = 0; c < cols; ++c) {
      for (int r = 0; r < rows; ++r) line[r] = (*mask)(r, c);
      double s = 0.0;
      for (int k = 0; k <= std::min(rows - 1, radius); ++k) s += line[k];
      for (int r = 0; r < rows; ++r) {
        (*mask)(r, c) = static_cast<float>(s) * inv;
        if (r + radius + 1 < rows) s += line[r + radius + 1];
        if (r - radius >= 0) s -= line[r - radius];
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Colours.

Colour Grey(double v) {
  return Colour(static_cast<float>(v), static_cast<float>(v), static_cast<float>(v));
}

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
    case 0:
      r = val;
      g = t;
      b = p;
      break;
    case 1:
      r = q;
      g = val;
      b = p;
      break;
    case 2:
      r = p;
      g = val;
      b = t;
      break;
    case 3:
      r = p;
      g = q;
      b = val;
      break;
    case 4:
      r = t;
      g = p;
      b = val;
      break;
    default:
      r = val;
      g = p;
      b = q;
      break;
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

// A colour with hue, saturation and value each drawn from its range (in that order).
Colour RandomHsv(Rng& rng, double hue_lo, double hue_hi, double sat_lo, double sat_hi,
                 double val_lo, double val_hi) {
  const double hue = rng.Uniform(hue_lo, hue_hi);
  const double sat = rng.Uniform(sat_lo, sat_hi);
  const double val = rng.Uniform(val_lo, val_hi);
  return Hsv(hue, sat, val);
}

// A texel of r, column drawn first.
cv::Point RandomPointIn(const cv::Rect& r, Rng& rng) {
  const int x = r.x + rng.Int(0, std::max(0, r.width - 1));
  const int y = r.y + rng.Int(0, std::max(0, r.height - 1));
  return cv::Point(x, y);
}

Colour Scale(const Colour& c, double k) { return c * static_cast<float>(k); }
cv::Scalar S(const Colour& c) { return cv::Scalar(c[0], c[1], c[2]); }

// ---------------------------------------------------------------------------------------------
// Canvas: the float image plus the metre <-> texel conversion.

struct Canvas {
  cv::Mat3f img;
  double ppm = 1.0;       // texels per metre
  double height_m = 0.0;  // surface height (metres)
  bool y_up = false;      // true: y is the height above the bottom edge (walls);
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
void Composite(Canvas& cv, cv::Point tl, const cv::Mat1f& mask, const Colour& colour, float alpha) {
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
  const double shade = rich ? rng.Uniform(0.8, 1.2) : rng.Uniform(0.95, 1.05);
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
    AddNoise(cv, leaf_r, rng.Fork(), cv.ppm * 0.15, cv.ppm * 0.15, rich ? 5.f : 1.5f);
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
        std::vector<cv::Point> poly = {{x0, g.y + g.height},
                                       {x0 + cv.L(w), g.y + g.height},
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
// Printed matter: text-like rows, pictures, posters, boards.

// The part of the canvas inside r, clipped to the image: content drawn on it cannot spill out.
cv::Mat3f View(Canvas& cv, const cv::Rect& r) { return cv.img(cv.Clip(r)); }

float Luma(const Colour& c) { return 0.114f * c[0] + 0.587f * c[1] + 0.299f * c[2]; }

// Dark or light ink, whichever reads on `background`.
Colour InkFor(const Colour& background, Rng& rng) {
  return Luma(background) > 140.f ? Grey(rng.Uniform(15.0, 70.0)) : Grey(rng.Uniform(220.0, 250.0));
}

void FillMat(cv::Mat3f& m, const cv::Rect& r, const Colour& c) {
  const cv::Rect k = r & cv::Rect(0, 0, m.cols, m.rows);
  if (!k.empty()) m(k).setTo(S(c));
}

// Linear gradient from c0 to c1 over r of m (top to bottom, or left to right).
void GradientMat(cv::Mat3f& m, const cv::Rect& r, const Colour& c0, const Colour& c1,
                 bool vertical) {
  const cv::Rect k = r & cv::Rect(0, 0, m.cols, m.rows);
  const int n = vertical ? r.height : r.width;
  for (int y = k.y; y < k.br().y; ++y) {
    cv::Vec3f* row = m.ptr<cv::Vec3f>(y);
    for (int x = k.x; x < k.br().x; ++x) {
      const float t = ((vertical ? y - r.y : x - r.x) + 0.5f) / static_cast<float>(n);
      row[x] = c0 + (c1 - c0) * t;
    }
  }
}

// Rows of letter-like blobs imitating print inside r (texels of m): x-height xh texels, line
// pitch about 2 xh, words of 1..9 letters of varied shapes, ragged line ends, blank lines.
// Below 2.5 texels of x-height a word is a single blob.
void DrawText(cv::Mat3f& m, const cv::Rect& r, double xh, const Colour& colour, Rng& rng) {
  if (r.width < 3 || r.height < 2) return;
  xh = std::max(1.0, xh);
  const double pitch = std::max(2.0 * xh, xh + 2.0);
  const cv::Scalar c = S(colour);
  const int lines = std::max(1, static_cast<int>(r.height / pitch));
  const int ixh = static_cast<int>(std::lround(xh));
  for (int l = 0; l < lines; ++l) {
    if (l > 0 && rng.Chance(0.08)) continue;  // blank line between paragraphs
    const int base = r.y + static_cast<int>(std::lround(l * pitch + 0.5 * (pitch + xh)));
    const int top = base - ixh;
    const double fill = rng.Chance(0.25) ? rng.Uniform(0.2, 0.8) : rng.Uniform(0.85, 1.0);
    const double end = r.x + fill * r.width;
    double x = r.x;
    while (x < end) {
      const int letters = rng.Int(1, 9);
      if (xh < 2.5) {
        const double ww = letters * xh * 0.9;
        const int x0 = static_cast<int>(std::lround(x));
        const int x1 = static_cast<int>(std::lround(std::min(x + ww, end))) - 1;
        if (x1 >= x0) cv::rectangle(m, cv::Point(x0, top), cv::Point(x1, base - 1), c, cv::FILLED);
        x += ww + std::max(1.0, xh);
        continue;
      }
      for (int i = 0; i < letters; ++i) {
        const double lw = xh * rng.Uniform(0.5, 0.9);
        if (x + lw > end) break;
        const int shape = rng.Int(0, 5);
        const int x0 = static_cast<int>(std::lround(x));
        const int x1 = std::max(x0 + 1, static_cast<int>(std::lround(x + lw)) - 1);
        const int stem = std::max(1, static_cast<int>(std::lround(xh * 0.22)));
        const int asc = static_cast<int>(std::lround(xh * 0.6));
        switch (shape) {
          case 0:  // round letter (o, e, c)
            cv::ellipse(m, cv::Point((x0 + x1) / 2, top + ixh / 2),
                        cv::Size(std::max(1, (x1 - x0) / 2), std::max(1, ixh / 2)), 0, 0, 360, c,
                        stem);
            break;
          case 1:  // ascender and bowl (b, d, h)
            cv::rectangle(m, cv::Point(x0, top - asc), cv::Point(x0 + stem - 1, base - 1), c,
                          cv::FILLED);
            cv::rectangle(m, cv::Point(x0, top + ixh / 3), cv::Point(x1, base - 1), c, stem);
            break;
          case 2:  // descender (p, q, g, y)
            cv::rectangle(m, cv::Point(x1 - stem + 1, top), cv::Point(x1, base - 1 + asc), c,
                          cv::FILLED);
            cv::rectangle(m, cv::Point(x0, top), cv::Point(x1, base - 1 - ixh / 3), c, stem);
            break;
          case 3:  // arch (n, m, u)
            cv::rectangle(m, cv::Point(x0, top), cv::Point(x0 + stem - 1, base - 1), c, cv::FILLED);
            cv::rectangle(m, cv::Point(x1 - stem + 1, top), cv::Point(x1, base - 1), c, cv::FILLED);
            cv::rectangle(m, cv::Point(x0, top), cv::Point(x1, top + stem - 1), c, cv::FILLED);
            break;
          case 4:  // thin tall letter (i, l, t)
            cv::rectangle(m, cv::Point(x0, top - asc / 2), cv::Point(x0 + stem - 1, base - 1), c,
                          cv::FILLED);
            x -= lw * 0.5;
            break;
          default:  // diagonal letter (v, x, z, s)
            cv::line(m, cv::Point(x0, top), cv::Point(x1, base - 1), c, stem);
            cv::line(m, cv::Point(x1, top), cv::Point(x0, base - 1), c, stem);
            break;
        }
        x += lw + std::max(1.0, xh * 0.2);
      }
      x += std::max(2.0, xh * 0.7);
    }
  }
}

// A random picture filling m: a landscape, an abstract composition or a photo-like scene.
void DrawPicture(cv::Mat3f& m, Rng& rng) {
  const int w = m.cols, h = m.rows;
  if (w < 3 || h < 3) return;
  const int type = rng.Int(0, 2);
  if (type == 0) {  // landscape: sky, sun, hills, ground, trees or houses
    const int hy = static_cast<int>(h * rng.Uniform(0.35, 0.7));
    const Colour sky0 = RandomHsv(rng, 190.0, 230.0, 0.3, 0.7, 150.0, 230.0);
    const Colour sky1 = RandomHsv(rng, 20.0, 220.0, 0.05, 0.3, 200.0, 250.0);
    GradientMat(m, cv::Rect(0, 0, w, hy), sky0, sky1, true);
    if (rng.Chance(0.5)) {
      const int sx = rng.Int(0, w - 1);
      const int sy = static_cast<int>(hy * rng.Uniform(0.15, 0.7));
      const int sr = std::max(1, static_cast<int>(h * rng.Uniform(0.04, 0.12)));
      cv::circle(m, cv::Point(sx, sy), sr, S(Hsv(rng.Uniform(20.0, 60.0), 0.5, 250.0)), cv::FILLED);
    }
    const int hills = rng.Int(1, 4);
    for (int i = 0; i < hills; ++i) {
      const int cx = rng.Int(0, w - 1);
      const int ax = std::max(2, static_cast<int>(w * rng.Uniform(0.2, 0.8)));
      const int ay = std::max(2, static_cast<int>(h * rng.Uniform(0.05, 0.35)));
      const Colour hc = RandomHsv(rng, 60.0, 230.0, 0.15, 0.6, 50.0, 170.0);
      if (rng.Chance(0.5)) {
        cv::ellipse(m, cv::Point(cx, hy), cv::Size(ax, ay), 0, 180, 360, S(hc), cv::FILLED);
      } else {
        const int peak = rng.Int(-ax / 2, ax / 2);
        std::vector<cv::Point> tri = {{cx - ax, hy}, {cx + ax, hy}, {cx + peak, hy - ay}};
        cv::fillConvexPoly(m, tri, S(hc));
      }
    }
    const Colour g0 = RandomHsv(rng, 40.0, 130.0, 0.3, 0.7, 80.0, 180.0);
    GradientMat(m, cv::Rect(0, hy, w, h - hy), g0, Scale(g0, 0.6), true);
    const int things = rng.Int(0, 6);
    for (int i = 0; i < things; ++i) {
      const int tx = rng.Int(0, w - 1);
      const int ty = hy + static_cast<int>((h - hy) * rng.Uniform(0.0, 0.8));
      const int th = std::max(3, static_cast<int>(h * rng.Uniform(0.08, 0.3)));
      if (rng.Chance(0.6)) {  // tree
        cv::rectangle(m, cv::Point(tx, ty - th / 2), cv::Point(tx + std::max(1, th / 10), ty),
                      S(Colour(30, 50, 70)), cv::FILLED);
        const Colour leaves = RandomHsv(rng, 70.0, 150.0, 0.4, 0.8, 40.0, 140.0);
        cv::ellipse(m, cv::Point(tx, ty - th / 2),
                    cv::Size(std::max(1, th / 4), std::max(1, th / 3)), 0, 0, 360, S(leaves),
                    cv::FILLED);
      } else {  // house
        const int hw = std::max(2, static_cast<int>(th * rng.Uniform(0.6, 1.4)));
        const Colour wall = RandomColour(rng, 0.1, 0.5, 120.0, 240.0);
        cv::rectangle(m, cv::Point(tx, ty - th / 2), cv::Point(tx + hw, ty), S(wall), cv::FILLED);
        std::vector<cv::Point> roof = {
            {tx - 1, ty - th / 2}, {tx + hw + 1, ty - th / 2}, {tx + hw / 2, ty - th}};
        cv::fillConvexPoly(m, roof, S(RandomHsv(rng, 0.0, 30.0, 0.6, 0.6, 60.0, 160.0)));
        cv::rectangle(m, cv::Point(tx + hw / 3, ty - th / 4),
                      cv::Point(tx + hw / 3 + std::max(1, hw / 4), ty), S(Grey(40)), cv::FILLED);
      }
    }
  } else if (type == 1) {  // abstract composition
    FillMat(m, cv::Rect(0, 0, w, h), RandomColour(rng, 0.0, 0.6, 60.0, 250.0));
    const int shapes = rng.Int(4, 12);
    for (int i = 0; i < shapes; ++i) {
      const Colour c = RandomColour(rng, 0.2, 0.95, 30.0, 250.0);
      const int x = rng.Int(0, w - 1);
      const int y = rng.Int(0, h - 1);
      const int s = std::max(2, static_cast<int>(std::min(w, h) * rng.Uniform(0.08, 0.5)));
      const int kind = rng.Int(0, 3);
      if (kind == 0) {
        const int s2 = std::max(2, static_cast<int>(s * rng.Uniform(0.3, 1.5)));
        cv::rectangle(m, cv::Point(x, y), cv::Point(x + s, y + s2), S(c), cv::FILLED);
      } else if (kind == 1) {
        cv::circle(m, cv::Point(x, y), s / 2, S(c), cv::FILLED);
      } else if (kind == 2) {
        const int dx = rng.Int(-s, s);
        std::vector<cv::Point> tri = {{x, y}, {x + s, y + dx / 2}, {x + dx, y + s}};
        cv::fillConvexPoly(m, tri, S(c));
      } else {
        const int x2 = rng.Int(0, w - 1);
        const int y2 = rng.Int(0, h - 1);
        cv::line(m, cv::Point(x, y), cv::Point(x2, y2), S(c), std::max(1, s / 6));
      }
    }
  } else {  // photo-like: a room or a group of people against a gradient
    const Colour b0 = RandomColour(rng, 0.05, 0.5, 60.0, 230.0);
    const Colour b1 = RandomColour(rng, 0.05, 0.5, 40.0, 200.0);
    GradientMat(m, cv::Rect(0, 0, w, h), b0, b1, rng.Chance(0.5));
    const int people = rng.Int(1, 4);
    for (int i = 0; i < people; ++i) {
      const int cx = static_cast<int>(w * (i + rng.Uniform(0.2, 0.8)) / people);
      const int head = std::max(2, static_cast<int>(h * rng.Uniform(0.08, 0.16)));
      const int cy = static_cast<int>(h * rng.Uniform(0.3, 0.55));
      const Colour shirt = RandomColour(rng, 0.2, 0.9, 40.0, 230.0);
      cv::ellipse(m, cv::Point(cx, cy + 3 * head), cv::Size(2 * head, 2 * head), 0, 180, 360,
                  S(shirt), cv::FILLED);
      cv::rectangle(m, cv::Point(cx - 2 * head, cy + 3 * head), cv::Point(cx + 2 * head, h),
                    S(shirt), cv::FILLED);
      const Colour skin = RandomHsv(rng, 15.0, 35.0, 0.2, 0.6, 80.0, 230.0);
      cv::circle(m, cv::Point(cx, cy + head), head, S(skin), cv::FILLED);
      const Colour hair = RandomHsv(rng, 10.0, 40.0, 0.1, 0.7, 20.0, 180.0);
      cv::ellipse(m, cv::Point(cx, cy + head), cv::Size(head, head), 0, 180, 360, S(hair),
                  cv::FILLED);
    }
  }
}

// A poster or leaflet: paper or coloured ground, a title, then sections of pictures, text,
// icon rows, bar charts and call-out boxes, maybe a logo.
void DrawPoster(Canvas& cv, const cv::Rect& r, Rng& rng) {
  SoftShadow(cv, r, cv.L(0.003), cv.L(0.006), cv.L(0.005), 0.3f);
  cv::Mat3f m = View(cv, r);
  if (m.cols < 4 || m.rows < 4) return;
  const int w = m.cols, h = m.rows;
  const bool paper = rng.Chance(0.5);
  Colour bg = paper ? RandomHsv(rng, 30.0, 60.0, 0.0, 0.08, 225.0, 248.0)
                    : RandomColour(rng, 0.25, 0.85, 90.0, 235.0);
  FillMat(m, cv::Rect(0, 0, w, h), bg);
  if (rng.Chance(0.3)) {
    const Colour bg2 = RandomColour(rng, 0.2, 0.8, 90.0, 240.0);
    GradientMat(m, cv::Rect(0, 0, w, h), bg, bg2, true);
    bg = (bg + bg2) * 0.5f;
  }
  const Colour ink = InkFor(bg, rng);
  const Colour accent = RandomColour(rng, 0.5, 0.95, 60.0, 220.0);
  const int margin = std::max(1, static_cast<int>(w * rng.Uniform(0.04, 0.09)));
  int y = margin;
  if (rng.Chance(0.75)) {  // title, maybe on a band
    const int th = std::max(2, static_cast<int>(h * rng.Uniform(0.08, 0.2)));
    Colour title_ink = rng.Chance(0.5) ? accent : ink;
    if (rng.Chance(0.5)) {
      FillMat(m, cv::Rect(0, y - margin / 2, w, th + margin), accent);
      title_ink = InkFor(accent, rng);
    }
    DrawText(m, cv::Rect(margin, y, w - 2 * margin, th), th * rng.Uniform(0.3, 0.42), title_ink,
             rng);
    y += th + margin;
  }
  const double body_xh = std::max(1.0, w * rng.Uniform(0.012, 0.03));
  while (y < h - 2 * margin) {
    const int sh =
        std::min(h - margin - y, std::max(3, static_cast<int>(h * rng.Uniform(0.12, 0.4))));
    const cv::Rect s(margin, y, w - 2 * margin, sh);
    const int kind = rng.Int(0, 4);
    if (kind == 0) {  // picture, maybe beside text
      const int pw = std::max(2, static_cast<int>(s.width * rng.Uniform(0.4, 1.0)));
      const bool left = rng.Chance(0.5);
      const cv::Rect p(left ? s.x : s.br().x - pw, s.y, pw, s.height);
      cv::Mat3f pic = m(p & cv::Rect(0, 0, w, h));
      DrawPicture(pic, rng);
      if (pw < s.width * 0.8) {
        const int gap = std::max(1, margin / 2);
        const cv::Rect t(left ? p.br().x + gap : s.x, s.y, s.width - pw - gap, s.height);
        DrawText(m, t, body_xh, ink, rng);
      }
    } else if (kind == 1) {  // text
      DrawText(m, s, body_xh, ink, rng);
    } else if (kind == 2) {  // icon row with captions
      const int n = rng.Int(2, 4);
      const int cell = s.width / n;
      for (int i = 0; i < n; ++i) {
        const Colour c = rng.Chance(0.5) ? accent : RandomColour(rng, 0.4, 0.9, 60.0, 220.0);
        const int rad = std::max(1, std::min(cell, s.height) / 3);
        const cv::Point ctr(s.x + i * cell + cell / 2, s.y + rad + 1);
        if (rng.Chance(0.5)) {
          cv::circle(m, ctr, rad, S(c), cv::FILLED);
        } else {
          cv::rectangle(m, ctr - cv::Point(rad, rad), ctr + cv::Point(rad, rad), S(c), cv::FILLED);
        }
        DrawText(m,
                 cv::Rect(s.x + i * cell + 1, s.y + 2 * rad + 3, cell - 2, s.height - 2 * rad - 3),
                 body_xh * 0.8, ink, rng);
      }
    } else if (kind == 3) {  // bar chart
      const int n = rng.Int(3, 8);
      const int bw = std::max(1, s.width / (2 * n));
      for (int i = 0; i < n; ++i) {
        const int bh = static_cast<int>(s.height * rng.Uniform(0.1, 0.95));
        const Colour c = rng.Chance(0.3) ? RandomColour(rng, 0.4, 0.9, 60.0, 220.0) : accent;
        cv::rectangle(m, cv::Point(s.x + (2 * i + 1) * s.width / (2 * n), s.br().y - bh),
                      cv::Point(s.x + (2 * i + 1) * s.width / (2 * n) + bw - 1, s.br().y - 1), S(c),
                      cv::FILLED);
      }
      cv::line(m, cv::Point(s.x, s.br().y - 1), cv::Point(s.br().x - 1, s.br().y - 1), S(ink), 1);
    } else {  // call-out box
      const Colour box = rng.Chance(0.5) ? accent : RandomColour(rng, 0.1, 0.6, 150.0, 250.0);
      FillMat(m, s, box);
      const int pad = std::max(1, margin / 2);
      DrawText(m, cv::Rect(s.x + pad, s.y + pad, s.width - 2 * pad, s.height - 2 * pad), body_xh,
               InkFor(box, rng), rng);
    }
    y += sh + std::max(1, margin / 2);
  }
  if (rng.Chance(0.5)) {  // logo
    const int rad = std::max(1, margin);
    cv::circle(m, cv::Point(w - 2 * rad, h - 2 * rad), rad, S(accent), cv::FILLED);
    cv::circle(m, cv::Point(w - 2 * rad, h - 2 * rad), std::max(1, rad / 2), S(bg), cv::FILLED);
  }
}

// A cork or felt board in a frame with sheets, cards and leaflets pinned on it.
void DrawNoticeBoard(Canvas& cv, const cv::Rect& r, Rng& rng) {
  SoftShadow(cv, r, cv.L(0.005), cv.L(0.01), cv.L(0.01), 0.35f);
  const Colour frame = rng.Chance(0.6) ? Grey(rng.Uniform(170.0, 205.0))
                                       : Scale(Colour(50, 90, 130), rng.Uniform(0.7, 1.3));
  Fill(cv, r, frame);
  const int f = cv.L(rng.Uniform(0.015, 0.035));
  Bevel(cv, r, std::max(1, f / 2), 25.f, 30.f);
  const cv::Rect in(r.x + f, r.y + f, std::max(1, r.width - 2 * f), std::max(1, r.height - 2 * f));
  const Colour ground = rng.Chance(0.7) ? Scale(Colour(85, 135, 185), rng.Uniform(0.75, 1.1))
                                        : RandomColour(rng, 0.2, 0.5, 70.0, 150.0);
  Fill(cv, in, ground);
  AddNoise(cv, in, rng.Fork(), 1.5, 1.5, 14.f, 8.f);
  AddNoise(cv, in, rng.Fork(), cv.ppm * 0.04, cv.ppm * 0.04, 6.f);
  Bevel(cv, in, std::max(1, f / 3), -20.f, -10.f);
  const double area_m2 = in.area() / (cv.ppm * cv.ppm);
  const int sheets = 1 + static_cast<int>(area_m2 / 0.03 * rng.Uniform(0.5, 1.0));
  for (int i = 0; i < sheets; ++i) {
    const int size = rng.Int(0, 4);
    double sw = 0.21, sh = 0.297;      // A4 portrait
    if (size == 1) std::swap(sw, sh);  // A4 landscape
    if (size == 2) {
      sw = 0.148;
      sh = 0.21;
    }  // A5
    if (size == 3) {
      sw = rng.Uniform(0.07, 0.15);
      sh = rng.Uniform(0.05, 0.1);
    }  // card
    if (size == 4) {
      sw = rng.Uniform(0.1, 0.2);
      sh = rng.Uniform(0.1, 0.25);
    }  // leaflet
    const int pw = std::min(in.width, cv.L(sw)), ph = std::min(in.height, cv.L(sh));
    const int px = in.x + rng.Int(0, std::max(0, in.width - pw));
    const int py = in.y + rng.Int(0, std::max(0, in.height - ph));
    const cv::Rect p(px, py, pw, ph);
    if (size == 4 && rng.Chance(0.6)) {
      DrawPoster(cv, p, rng);
    } else {
      const Colour paper = rng.Chance(0.7) ? Grey(rng.Uniform(228.0, 250.0))
                                           : RandomColour(rng, 0.15, 0.45, 200.0, 250.0);
      SoftShadow(cv, p, cv.L(0.002), cv.L(0.004), cv.L(0.003), 0.3f);
      Fill(cv, p, paper);
      cv::Mat3f m = View(cv, p);
      const int margin = std::max(1, m.cols / 10);
      int y = margin;
      if (rng.Chance(0.7)) {  // heading
        const int th = std::max(2, m.rows / 8);
        const Colour c = rng.Chance(0.5) ? Grey(20) : RandomColour(rng, 0.5, 0.9, 50.0, 180.0);
        DrawText(m, cv::Rect(margin, y, m.cols - 2 * margin, th), th * 0.45, c, rng);
        y += th + margin / 2;
      }
      if (rng.Chance(0.3) && m.rows - y > 3 * margin) {
        const int ph2 = (m.rows - y) / 3;
        cv::Mat3f pic =
            m(cv::Rect(margin, y, m.cols - 2 * margin, ph2) & cv::Rect(0, 0, m.cols, m.rows));
        DrawPicture(pic, rng);
        y += ph2 + margin / 2;
      }
      const double xh_m = rng.Uniform(0.003, 0.006);
      const double ink = rng.Uniform(20.0, 80.0);
      DrawText(m, cv::Rect(margin, y, m.cols - 2 * margin, m.rows - y - margin),
               std::max(1.0, cv.ppm * xh_m), Grey(ink), rng);
    }
    // Pins: one at the top, or one in each top corner.
    const Colour pin = RandomColour(rng, 0.6, 0.95, 120.0, 240.0);
    const int pr = cv.L(0.006, 1);
    const int pins = rng.Chance(0.7) ? 1 : 2;
    for (int k = 0; k < pins; ++k) {
      const cv::Point c = pins == 1
                              ? cv::Point(p.x + p.width / 2, p.y + pr + 1)
                              : cv::Point(k == 0 ? p.x + pr + 1 : p.br().x - pr - 2, p.y + pr + 1);
      cv::circle(cv.img, c + cv::Point(1, 1), pr, S(Grey(40)), cv::FILLED);
      cv::circle(cv.img, c, pr, S(pin), cv::FILLED);
    }
  }
}

// A framed picture: frame, maybe a mount, the picture, maybe a reflection on the glass.
void DrawFramedPicture(Canvas& cv, const cv::Rect& r, Rng& rng) {
  SoftShadow(cv, r, cv.L(0.006), cv.L(0.012), cv.L(0.012), 0.4f);
  const int style = rng.Int(0, 3);
  const Colour frame = style == 0   ? Grey(rng.Uniform(20.0, 50.0))
                       : style == 1 ? Scale(Colour(45, 85, 130), rng.Uniform(0.7, 1.3))
                       : style == 2 ? Colour(60, 150, 195)
                                    : Grey(rng.Uniform(170.0, 210.0));
  Fill(cv, r, frame);
  const int f = cv.L(rng.Uniform(0.012, 0.05));
  Bevel(cv, r, std::max(1, f / 2), 30.f, 35.f);
  cv::Rect in(r.x + f, r.y + f, std::max(1, r.width - 2 * f), std::max(1, r.height - 2 * f));
  if (rng.Chance(0.6)) {  // mount
    Fill(cv, in, Grey(rng.Uniform(225.0, 248.0)));
    const int mt = cv.L(rng.Uniform(0.02, 0.07));
    in = cv::Rect(in.x + mt, in.y + mt, std::max(1, in.width - 2 * mt),
                  std::max(1, in.height - 2 * mt));
    Bevel(cv, in, 1, -30.f, -20.f);
  }
  cv::Mat3f pic = View(cv, in);
  DrawPicture(pic, rng);
  if (rng.Chance(0.5)) {  // reflection band on the glass
    cv::Mat1f mask = cv::Mat1f::zeros(pic.size());
    const int x0 = rng.Int(0, std::max(0, mask.cols - 1));
    const int bw = std::max(2, static_cast<int>(mask.cols * rng.Uniform(0.1, 0.3)));
    std::vector<cv::Point> band = {{x0, mask.rows},
                                   {x0 + bw, mask.rows},
                                   {x0 + bw + mask.rows / 2, 0},
                                   {x0 + mask.rows / 2, 0}};
    cv::fillConvexPoly(mask, band, cv::Scalar(1.0));
    Composite(cv, cv.Clip(in).tl(), mask, Grey(255), static_cast<float>(rng.Uniform(0.1, 0.25)));
  }
}

// A whiteboard: aluminium frame, ghosts of old writing, handwriting and diagrams, a pen tray.
void DrawWhiteboard(Canvas& cv, const cv::Rect& r, Rng& rng) {
  SoftShadow(cv, r, cv.L(0.005), cv.L(0.01), cv.L(0.01), 0.3f);
  Fill(cv, r, Grey(rng.Uniform(175.0, 205.0)));
  const int f = cv.L(0.018);
  Bevel(cv, r, std::max(1, f / 2), 25.f, 35.f);
  const cv::Rect in(r.x + f, r.y + f, std::max(1, r.width - 2 * f), std::max(1, r.height - 2 * f));
  Fill(cv, in, RandomHsv(rng, 180.0, 220.0, 0.02, 0.02, 235.0, 250.0));
  const int ghosts = rng.Int(1, 5);
  for (int i = 0; i < ghosts; ++i) {
    const cv::Point c = RandomPointIn(in, rng);
    const double ax_x = rng.Uniform(0.05, 0.2);
    const double ax_y = rng.Uniform(0.05, 0.15);
    const cv::Size ax(std::max(1, static_cast<int>(in.width * ax_x)),
                      std::max(1, static_cast<int>(in.height * ax_y)));
    SoftBlob(cv, c, ax, 0.0, Grey(200), static_cast<float>(rng.Uniform(0.1, 0.3)), cv.L(0.01));
  }
  cv::Mat3f m = View(cv, in);
  const int items = rng.Int(2, 9);
  for (int i = 0; i < items; ++i) {
    const int hue = rng.Int(0, 3);
    const Colour pen = hue == 0   ? Colour(30, 30, 30)
                       : hue == 1 ? Colour(160, 60, 30)
                       : hue == 2 ? Colour(40, 40, 180)
                                  : Colour(50, 130, 40);
    const int t = std::max(1, cv.L(0.003));
    const int x0 = rng.Int(0, std::max(0, m.cols - 1));
    const int y0 = rng.Int(0, std::max(0, m.rows - 1));
    if (rng.Chance(0.6)) {  // handwriting: zig-zag strokes along a few lines
      const int lines = rng.Int(1, 4);
      const int xh = cv.L(rng.Uniform(0.012, 0.03), 2);
      const int len = static_cast<int>(m.cols * rng.Uniform(0.15, 0.5));
      for (int l = 0; l < lines; ++l) {
        std::vector<cv::Point> pts;
        int x = x0;
        const int base = y0 + l * 2 * xh;
        while (x < x0 + len) {
          const int up = rng.Int(0, 2);
          pts.push_back(cv::Point(x, base - (up == 0 ? xh : up == 1 ? xh / 2 : 0)));
          x += std::max(1, xh / 3 + rng.Int(0, xh / 2));
          if (rng.Chance(0.12)) {
            cv::polylines(m, pts, false, S(pen), t, cv::LINE_8);
            pts.clear();
            x += xh;
          }
        }
        if (pts.size() > 1) cv::polylines(m, pts, false, S(pen), t, cv::LINE_8);
      }
    } else {  // diagram: box, circle or arrow
      const int s =
          std::max(3, static_cast<int>(std::min(m.cols, m.rows) * rng.Uniform(0.1, 0.35)));
      const int kind = rng.Int(0, 2);
      if (kind == 0) {
        const int s2 = std::max(3, static_cast<int>(s * rng.Uniform(0.4, 1.2)));
        cv::rectangle(m, cv::Point(x0, y0), cv::Point(x0 + s, y0 + s2), S(pen), t);
      } else if (kind == 1) {
        cv::circle(m, cv::Point(x0, y0), s / 2, S(pen), t);
      } else {
        const int dx = rng.Int(-s, s);
        const int dy = rng.Int(-s / 2, s / 2);
        cv::arrowedLine(m, cv::Point(x0, y0), cv::Point(x0 + dx, y0 + dy), S(pen), t, cv::LINE_8, 0,
                        0.2);
      }
    }
  }
  // Pen tray with a few markers.
  const cv::Rect tray(r.x + f, r.br().y - f, r.width - 2 * f, f);
  Fill(cv, tray, Grey(150));
  const int pens = rng.Int(0, 3);
  for (int i = 0; i < pens; ++i) {
    const int px = tray.x + rng.Int(0, std::max(0, tray.width - cv.L(0.13)));
    Fill(cv, cv::Rect(px, tray.y - std::max(1, f / 2), cv.L(0.13), std::max(1, f / 2)),
         RandomColour(rng, 0.5, 0.9, 40.0, 200.0));
  }
}

// ---------------------------------------------------------------------------------------------
// Wall fixtures.

// A switch (rockers) or socket (holes) plate of one or two gangs, bottom-left corner at
// (x_m, y_m).
void DrawPlate(Canvas& cv, double x_m, double y_m, bool socket, Rng& rng) {
  const int gangs = rng.Int(1, 2);
  const double s = rng.Uniform(0.075, 0.09);
  const cv::Rect r = cv.R(x_m, y_m, s * gangs, s);
  SoftShadow(cv, r, cv.L(0.002), cv.L(0.004), cv.L(0.004), 0.35f);
  const Colour plate =
      rng.Chance(0.8) ? Grey(rng.Uniform(225.0, 248.0)) : Grey(rng.Uniform(140.0, 190.0));
  Fill(cv, r, plate);
  Bevel(cv, r, cv.L(0.004), 15.f, 30.f);
  for (int g = 0; g < gangs; ++g) {
    const double gx = x_m + g * s;
    if (socket) {
      const double tilt = rng.Uniform(-0.004, 0.004);
      Fill(cv, cv.R(gx + s * 0.3, y_m + s * 0.35 + tilt, 0.006, 0.013), Grey(35));
      Fill(cv, cv.R(gx + s * 0.62, y_m + s * 0.35 - tilt, 0.006, 0.013), Grey(35));
      if (rng.Chance(0.5)) Fill(cv, cv.R(gx + s * 0.46, y_m + s * 0.65, 0.007, 0.01), Grey(35));
    } else {
      const cv::Rect k = cv.R(gx + s * 0.3, y_m + s * 0.2, s * 0.4, s * 0.6);
      Fill(cv, k, plate + Grey(-12));
      Bevel(cv, k, cv.L(0.003), 18.f, 30.f);
    }
  }
}

// A sign plate: exit (green), information (blue), fire (red), caution (yellow) or a room plate.
void DrawSign(Canvas& cv, const cv::Rect& r, Rng& rng) {
  SoftShadow(cv, r, cv.L(0.002), cv.L(0.004), cv.L(0.004), 0.3f);
  const int kind = rng.Int(0, 4);
  const Colour bg = kind == 0   ? Colour(70, 140, 20)
                    : kind == 1 ? Colour(150, 80, 20)
                    : kind == 2 ? Colour(40, 30, 190)
                    : kind == 3 ? Colour(30, 200, 240)
                                : Grey(rng.Uniform(150.0, 245.0));
  Fill(cv, r, bg);
  cv::Mat3f m = View(cv, r);
  if (m.cols < 4 || m.rows < 4) return;
  const Colour ink = kind == 3 ? Grey(20) : kind == 4 ? InkFor(bg, rng) : Grey(245);
  const int h = m.rows, w = m.cols;
  const int pic = std::min(h, w / 2);  // pictogram square on the left
  const cv::Point c(pic / 2, h / 2);
  const int u = std::max(1, pic / 8);
  if (kind == 0) {  // running figure and an arrow
    cv::circle(m, c + cv::Point(u, -3 * u), u, S(ink), cv::FILLED);
    cv::line(m, c + cv::Point(u, -2 * u), c + cv::Point(-u, u), S(ink), u);
    cv::line(m, c + cv::Point(-u, u), c + cv::Point(-3 * u, 3 * u), S(ink), u);
    cv::line(m, c + cv::Point(-u, u), c + cv::Point(u, 3 * u), S(ink), u);
    cv::line(m, c + cv::Point(0, -u), c + cv::Point(2 * u, 0), S(ink), u);
    cv::arrowedLine(m, cv::Point(pic, h / 2), cv::Point(w - u, h / 2), S(ink), std::max(1, u),
                    cv::LINE_8, 0, 0.3);
  } else if (kind == 1) {  // "i" in a circle, then text
    cv::circle(m, c, std::max(1, pic / 2 - u), S(ink), cv::FILLED);
    cv::rectangle(m, c + cv::Point(-u / 2, -u), c + cv::Point(u / 2, 2 * u), S(bg), cv::FILLED);
    cv::circle(m, c + cv::Point(0, -2 * u), std::max(1, u / 2), S(bg), cv::FILLED);
    DrawText(m, cv::Rect(pic, h / 5, w - pic - u, 3 * h / 5), h * 0.15, ink, rng);
  } else if (kind == 2) {  // flame
    std::vector<cv::Point> flame = {c + cv::Point(0, -3 * u), c + cv::Point(2 * u, 2 * u),
                                    c + cv::Point(-2 * u, 2 * u)};
    cv::fillConvexPoly(m, flame, S(ink));
    cv::circle(m, c + cv::Point(0, u), 2 * u, S(ink), cv::FILLED);
    DrawText(m, cv::Rect(pic, h / 4, w - pic - u, h / 2), h * 0.18, ink, rng);
  } else if (kind == 3) {  // warning triangle
    std::vector<cv::Point> tri = {c + cv::Point(0, -3 * u), c + cv::Point(3 * u, 3 * u),
                                  c + cv::Point(-3 * u, 3 * u)};
    cv::polylines(m, tri, true, S(ink), std::max(1, u / 2));
    cv::line(m, c + cv::Point(0, -u), c + cv::Point(0, u), S(ink), std::max(1, u / 2));
    DrawText(m, cv::Rect(pic, h / 5, w - pic - u, 3 * h / 5), h * 0.15, ink, rng);
  } else {  // room plate: a big number and a few lines
    DrawText(m, cv::Rect(u, u, w / 3, h - 2 * u), h * 0.45, ink, rng);
    DrawText(m, cv::Rect(w / 3 + 2 * u, h / 6, 2 * w / 3 - 3 * u, 2 * h / 3), h * 0.1, ink, rng);
  }
}

// A panel radiator of w_m x h_m with its bottom at y_m: irregular faint grooves, a convector
// grille on top, a valve and pipes down to the floor.
void DrawRadiator(Canvas& cv, double x_m, double y_m, double w_m, double h_m, Rng& rng) {
  const Colour body = Grey(rng.Uniform(205.0, 240.0));
  const Colour pipe = rng.Chance(0.5) ? body : Grey(rng.Uniform(140.0, 190.0));
  const bool right = rng.Chance(0.5);
  const double pipe_w = rng.Uniform(0.012, 0.02);
  for (int side = 0; side < 2; ++side) {
    const double px = side == 0 ? x_m + 0.03 : x_m + w_m - 0.03 - pipe_w;
    const cv::Rect p = cv.R(px, 0.0, pipe_w, y_m + 0.05);
    SoftShadow(cv, p, cv.L(0.003), 0, cv.L(0.004), 0.3f);
    Fill(cv, p, pipe);
    Shift(cv, cv::Rect(p.x, p.y, std::max(1, p.width / 3), p.height), Grey(15));
  }
  const cv::Rect r = cv.R(x_m, y_m, w_m, h_m);
  SoftShadow(cv, r, cv.L(0.006), cv.L(0.012), cv.L(0.015), 0.35f);
  Fill(cv, r, body);
  // Grooves at irregular pitch.
  double gx = x_m + rng.Uniform(0.01, 0.04);
  while (gx < x_m + w_m - 0.01) {
    const int c = cv.X(gx);
    Shift(cv, cv::Rect(c, r.y + cv.L(0.02), 1, std::max(1, r.height - cv.L(0.04))), Grey(-9));
    Shift(cv, cv::Rect(c + 1, r.y + cv.L(0.02), 1, std::max(1, r.height - cv.L(0.04))), Grey(5));
    gx += rng.Uniform(0.03, 0.06);
  }
  // Convector grille on top: dark slots of uneven lengths.
  const cv::Rect top = cv.R(x_m, y_m + h_m - 0.02, w_m, 0.02);
  Fill(cv, top, Scale(body, 0.75));
  double sx = x_m + 0.01;
  while (sx < x_m + w_m - 0.02) {
    const double sl = rng.Uniform(0.02, 0.08);
    Fill(cv, cv.R(sx, y_m + h_m - 0.015, std::min(sl, x_m + w_m - 0.01 - sx), 0.01), Grey(60));
    sx += sl + rng.Uniform(0.004, 0.012);
  }
  Bevel(cv, r, cv.L(0.006), 15.f, 40.f);
  // Valve with a cap on one end.
  const double vx = right ? x_m + w_m + 0.005 : x_m - 0.045;
  const cv::Rect valve = cv.R(vx, y_m - 0.02, 0.04, 0.06);
  Fill(cv, valve, Grey(rng.Uniform(170.0, 230.0)));
  Bevel(cv, valve, cv.L(0.004), 25.f, 35.f);
  cv::circle(cv.img, cv.P(vx + 0.02, y_m + 0.065), cv.L(0.022), S(Grey(rng.Uniform(200.0, 245.0))),
             cv::FILLED);
  cv::circle(cv.img, cv.P(vx + 0.02, y_m + 0.065), cv.L(0.022), S(Grey(120)), 1);
  // Dust and a few marks.
  const int dust = rng.Int(0, 3);
  for (int i = 0; i < dust; ++i) {
    const double dx = rng.Uniform(0.0, w_m);
    const double dy = rng.Uniform(0.0, h_m);
    const double rx = rng.Uniform(0.02, 0.08);
    const double ry = rng.Uniform(0.01, 0.04);
    const double alpha = rng.Uniform(0.1, 0.3);
    SoftBlob(cv, cv.P(x_m + dx, y_m + dy), cv::Size(cv.L(rx), cv.L(ry)), 0.0, Colour(150, 170, 180),
             static_cast<float>(alpha), cv.L(0.01));
  }
}

// A fire extinguisher on its bracket, standing with its bottom at y_m.
void DrawExtinguisher(Canvas& cv, double x_m, double y_m, Rng& rng) {
  const double w = rng.Uniform(0.12, 0.17);
  const double h = rng.Uniform(0.4, 0.6);
  const Colour red = Scale(Colour(35, 30, 195), rng.Uniform(0.8, 1.1));
  const cv::Rect bracket = cv.R(x_m - 0.01, y_m + h * 0.55, w + 0.02, 0.04);
  Fill(cv, bracket, Grey(90));
  const cv::Rect body = cv.R(x_m, y_m, w, h - w / 2);
  SoftShadow(cv, body, cv.L(0.01), cv.L(0.015), cv.L(0.015), 0.4f);
  Fill(cv, body, red);
  cv::ellipse(cv.img, cv.P(x_m + w / 2, y_m + h - w / 2), cv::Size(cv.L(w / 2), cv.L(w / 3)), 0,
              180, 360, S(red), cv::FILLED);
  // Cylinder shading.
  Shift(cv, cv::Rect(body.x + body.width / 6, body.y, std::max(1, body.width / 5), body.height),
        Grey(35));
  Shift(cv,
        cv::Rect(body.br().x - body.width / 4, body.y, std::max(1, body.width / 4), body.height),
        Grey(-45));
  // Label with a colour band and text.
  const cv::Rect label = cv.R(x_m + w * 0.15, y_m + h * 0.2, w * 0.7, h * 0.35);
  Fill(cv, label, Grey(235));
  const int band = rng.Int(0, 2);
  Fill(cv, cv.R(x_m + w * 0.15, y_m + h * 0.5, w * 0.7, h * 0.05),
       band == 0   ? Colour(140, 220, 240)
       : band == 1 ? Colour(160, 80, 20)
                   : Grey(20));
  cv::Mat3f m = View(cv, label);
  DrawText(m, cv::Rect(1, 1, m.cols - 2, m.rows - 2), std::max(1.0, cv.ppm * 0.006), Grey(30), rng);
  // Valve head, lever and hose.
  const double top = y_m + h - w / 6;
  Fill(cv, cv.R(x_m + w * 0.35, top, w * 0.3, 0.05), Grey(rng.Uniform(40.0, 190.0)));
  cv::line(cv.img, cv.P(x_m + w * 0.5, top + 0.05), cv.P(x_m + w * 1.2, top + 0.07), S(Grey(30)),
           cv.L(0.01));
  const std::vector<cv::Point> hose = {
      cv.P(x_m + w * 0.6, top + 0.02), cv.P(x_m + w * 1.15, top - 0.03),
      cv.P(x_m + w * 1.2, y_m + h * 0.3), cv.P(x_m + w * 1.05, y_m + h * 0.15)};
  cv::polylines(cv.img, hose, false, S(Grey(25)), cv.L(0.014));
}

// Small wall fixtures: fire-alarm call point, hand sanitiser, thermostat, clock, CCTV dome.
// Returns the width used (metres).
double DrawSmallFixture(Canvas& cv, double x_m, Rng& rng) {
  const int kind = rng.Int(0, 3);
  if (kind == 0) {  // call point: red box, white window, black button
    const double s = rng.Uniform(0.085, 0.1);
    const double y = rng.Uniform(1.3, 1.5);
    const cv::Rect r = cv.R(x_m, y, s, s);
    SoftShadow(cv, r, cv.L(0.004), cv.L(0.008), cv.L(0.006), 0.4f);
    Fill(cv, r, Colour(40, 35, 200));
    Bevel(cv, r, cv.L(0.005), 30.f, 40.f);
    Fill(cv, cv.R(x_m + s * 0.2, y + s * 0.2, s * 0.6, s * 0.6), Grey(235));
    Fill(cv, cv.R(x_m + s * 0.42, y + s * 0.42, s * 0.16, s * 0.16), Grey(30));
    return s;
  }
  if (kind == 1) {  // sanitiser dispenser
    const double w = rng.Uniform(0.1, 0.13), h = rng.Uniform(0.2, 0.27);
    const double y = rng.Uniform(1.1, 1.3);
    const cv::Rect r = cv.R(x_m, y, w, h);
    SoftShadow(cv, r, cv.L(0.008), cv.L(0.012), cv.L(0.01), 0.4f);
    Fill(cv, r, Grey(rng.Uniform(220.0, 245.0)));
    Bevel(cv, r, cv.L(0.006), 15.f, 40.f);
    Fill(cv, cv.R(x_m + w * 0.3, y + h * 0.45, w * 0.4, h * 0.25), Colour(150, 140, 120));
    Fill(cv, cv.R(x_m + w * 0.1, y, w * 0.8, h * 0.15), Grey(rng.Uniform(30.0, 120.0)));
    return w;
  }
  if (kind == 2) {  // thermostat with a display
    const double w = rng.Uniform(0.07, 0.1), h = rng.Uniform(0.1, 0.13);
    const double y = rng.Uniform(1.35, 1.55);
    const cv::Rect r = cv.R(x_m, y, w, h);
    SoftShadow(cv, r, cv.L(0.003), cv.L(0.006), cv.L(0.005), 0.35f);
    Fill(cv, r, Grey(rng.Uniform(215.0, 240.0)));
    Bevel(cv, r, cv.L(0.004), 15.f, 30.f);
    Fill(cv, cv.R(x_m + w * 0.15, y + h * 0.55, w * 0.7, h * 0.3), Colour(90, 110, 80));
    cv::circle(cv.img, cv.P(x_m + w * 0.5, y + h * 0.25), cv.L(w * 0.12), S(Grey(160)), cv::FILLED);
    return w;
  }
  // Clock: rim, face, hour marks and two hands.
  const double rad = rng.Uniform(0.1, 0.16);
  const double y = rng.Uniform(1.85, 2.1);
  const cv::Point c = cv.P(x_m + rad, std::min(y, cv.height_m - rad - 0.05));
  cv::circle(cv.img, c + cv::Point(cv.L(0.006), cv.L(0.01)), cv.L(rad), S(Grey(120)), cv::FILLED);
  cv::circle(cv.img, c, cv.L(rad), S(Grey(rng.Uniform(20.0, 200.0))), cv::FILLED);
  cv::circle(cv.img, c, cv.L(rad * 0.88), S(Grey(rng.Uniform(225.0, 250.0))), cv::FILLED);
  for (int k = 0; k < 12; ++k) {
    const double a = k * M_PI / 6;
    const double r0 = k % 3 == 0 ? 0.65 : 0.75;
    cv::line(cv.img,
             c + cv::Point(static_cast<int>(cv.L(rad * r0) * std::cos(a)),
                           static_cast<int>(cv.L(rad * r0) * std::sin(a))),
             c + cv::Point(static_cast<int>(cv.L(rad * 0.82) * std::cos(a)),
                           static_cast<int>(cv.L(rad * 0.82) * std::sin(a))),
             S(Grey(30)), std::max(1, cv.L(0.004)));
  }
  const double hour = rng.Uniform(0.0, 2 * M_PI);
  const double minute = rng.Uniform(0.0, 2 * M_PI);
  cv::line(cv.img, c,
           c + cv::Point(static_cast<int>(cv.L(rad * 0.45) * std::sin(hour)),
                         -static_cast<int>(cv.L(rad * 0.45) * std::cos(hour))),
           S(Grey(20)), cv.L(0.008));
  cv::line(cv.img, c,
           c + cv::Point(static_cast<int>(cv.L(rad * 0.7) * std::sin(minute)),
                         -static_cast<int>(cv.L(rad * 0.7) * std::cos(minute))),
           S(Grey(20)), cv.L(0.005));
  return 2 * rad;
}

// High on the wall, between y0_m and the ceiling, from x_m: an emergency light, a speaker, a
// CCTV dome, a run of cable trunking with a junction box, or a hanging direction sign. Returns
// the width used (metres).
double DrawHighFixture(Canvas& cv, double x_m, double y0_m, double max_w_m, Rng& rng) {
  const double room = cv.height_m - 0.03 - y0_m;
  if (room < 0.1) return 0.0;
  const int kind = rng.Int(0, 4);
  if (kind == 0) {  // emergency light: white box with a translucent window and a green LED
    const double w = std::min(max_w_m, rng.Uniform(0.25, 0.38)),
                 h = std::min(room, rng.Uniform(0.08, 0.12));
    const double y = y0_m + rng.Uniform(0.0, room - h);
    const cv::Rect r = cv.R(x_m, y, w, h);
    SoftShadow(cv, r, cv.L(0.004), cv.L(0.008), cv.L(0.008), 0.35f);
    Fill(cv, r, Grey(rng.Uniform(225.0, 245.0)));
    Bevel(cv, r, cv.L(0.005), 12.f, 35.f);
    Fill(cv, cv.R(x_m + w * 0.1, y + h * 0.25, w * 0.8, h * 0.5), Grey(rng.Uniform(240.0, 252.0)));
    cv::circle(cv.img, cv.P(x_m + w * 0.05, y + h * 0.5), std::max(1, cv.L(0.004)),
               S(Colour(60, 200, 60)), cv::FILLED);
    return w;
  }
  if (kind == 1) {  // speaker: round grille with rings
    const double rad = std::min(room / 2, rng.Uniform(0.07, 0.12));
    const cv::Point c = cv.P(x_m + rad, y0_m + rng.Uniform(rad, room - rad));
    cv::circle(cv.img, c + cv::Point(cv.L(0.004), cv.L(0.008)), cv.L(rad), S(Grey(140)),
               cv::FILLED);
    cv::circle(cv.img, c, cv.L(rad), S(Grey(rng.Uniform(200.0, 240.0))), cv::FILLED);
    const int rings = rng.Int(2, 4);
    for (int k = 1; k <= rings; ++k)
      cv::circle(cv.img, c, cv.L(rad * k / (rings + 1.0)), S(Grey(rng.Uniform(90.0, 160.0))), 1);
    return 2 * rad;
  }
  if (kind == 2) {  // CCTV dome on a base plate
    const double rad = std::min(room / 2, rng.Uniform(0.05, 0.08));
    const cv::Point c = cv.P(x_m + rad, y0_m + rng.Uniform(rad, room - rad));
    cv::circle(cv.img, c, cv.L(rad), S(Grey(rng.Uniform(215.0, 240.0))), cv::FILLED);
    cv::circle(cv.img, c, cv.L(rad * 0.65), S(Grey(rng.Uniform(25.0, 60.0))), cv::FILLED);
    cv::circle(cv.img, c - cv::Point(cv.L(rad * 0.2), cv.L(rad * 0.2)),
               std::max(1, cv.L(rad * 0.15)), S(Grey(150)), cv::FILLED);
    return 2 * rad;
  }
  if (kind == 3) {  // cable trunking with a junction box and a drop down the wall
    const double w = std::min(max_w_m, rng.Uniform(0.5, 2.0));
    const double t = rng.Uniform(0.03, 0.06);
    const double y = y0_m + rng.Uniform(0.0, std::max(0.0, room - t));
    const Colour c = Grey(rng.Uniform(215.0, 242.0));
    const cv::Rect run = cv.R(x_m, y, w, t);
    SoftShadow(cv, run, 0, cv.L(0.006), cv.L(0.005), 0.3f);
    Fill(cv, run, c);
    Bevel(cv, run, std::max(1, cv.L(0.004)), 10.f, 30.f);
    const double bx = x_m + rng.Uniform(0.0, std::max(0.0, w - 0.1));
    const cv::Rect box = cv.R(bx, y - 0.02, 0.09, t + 0.04);
    Fill(cv, box, c + Grey(-8));
    Bevel(cv, box, std::max(1, cv.L(0.004)), 12.f, 30.f);
    if (rng.Chance(0.5)) {
      const double dx = bx + 0.03;
      const double drop = rng.Uniform(0.3, 0.9);
      const cv::Rect d = cv.R(dx, std::max(0.0, y - drop), 0.025, drop);
      Fill(cv, d, c);
      Bevel(cv, d, 1, 10.f, 25.f);
    }
    return w;
  }
  // Direction sign on two short chains: a coloured plate with an arrow and text.
  const double w = std::min(max_w_m, rng.Uniform(0.3, 0.6)),
               h = std::min(room, rng.Uniform(0.1, 0.18));
  const double y = y0_m + rng.Uniform(0.0, room - h);
  const cv::Rect r = cv.R(x_m, y, w, h);
  const Colour bg = RandomColour(rng, 0.4, 0.9, 70.0, 200.0);
  SoftShadow(cv, r, cv.L(0.004), cv.L(0.008), cv.L(0.008), 0.3f);
  Fill(cv, r, bg);
  cv::Mat3f m = View(cv, r);
  const Colour ink = InkFor(bg, rng);
  if (m.cols > 8 && m.rows > 4) {
    const bool left = rng.Chance(0.5);
    const int ah = m.rows / 2;
    cv::arrowedLine(m, cv::Point(left ? ah * 2 : ah / 2, m.rows / 2),
                    cv::Point(left ? ah / 2 : ah * 2, m.rows / 2), S(ink), std::max(1, ah / 4),
                    cv::LINE_8, 0, 0.4);
    DrawText(m, cv::Rect(ah * 5 / 2, m.rows / 4, m.cols - ah * 3, m.rows / 2), m.rows * 0.22, ink,
             rng);
  }
  return w;
}

// Fills the wall between two door frames (or a frame and a wall end), [a_m, b_m]: switches and
// room plates beside the doors; posters, notice boards, pictures, whiteboards, signs and small
// fixtures at eye height; radiators, extinguishers and sockets low down. Gaps between objects
// are random and shrink with `density`; every object draws its own size and content.
void FillWallSegment(Canvas& cv, double a_m, double b_m, bool door_left, bool door_right,
                     double density, double poster_share, Rng& rng) {
  if (b_m - a_m < 0.2) return;
  const double inv = 1.0 / std::max(density, 0.05);
  // Beside the doors.
  for (int side = 0; side < 2; ++side) {
    if (!(side == 0 ? door_left : door_right) || b_m - a_m < 0.4) continue;
    const bool plate = rng.Chance(std::min(1.0, 0.7 * density));
    const double px = rng.Uniform(0.05, 0.14);
    const double py = rng.Uniform(1.0, 1.15);
    if (plate) DrawPlate(cv, side == 0 ? a_m + px : b_m - px - 0.18, py, false, rng);
    if (rng.Chance(std::min(1.0, 0.6 * density))) {
      const double sw = rng.Uniform(0.12, 0.25);
      const double sh = rng.Uniform(0.07, 0.15);
      const double sx = rng.Uniform(0.05, 0.12);
      const double sy = rng.Uniform(1.45, 1.65);
      DrawSign(cv, cv.R(side == 0 ? a_m + sx : b_m - sx - sw, sy, sw, sh), rng);
    }
  }
  // Eye height.
  const double top_limit = cv.height_m - 0.08;
  double x = a_m + (door_left ? rng.Uniform(0.35, 0.6) : rng.Uniform(0.05, 0.5));
  const double end = b_m - (door_right ? 0.35 : 0.05);
  while (x < end - 0.1) {
    double u = rng.Uniform();
    // Another poster share: the other kinds keep their proportions over the rest (0.3 is the
    // default and leaves u as drawn, so default walls are unchanged bit for bit).
    if (poster_share != 0.3 && u >= poster_share)
      u = 0.3 + (u - poster_share) * (0.7 / (1.0 - poster_share));
    else if (poster_share != 0.3)
      u = 0.0;
    double w = 0.0, h = 0.0, y = 0.0;
    int kind = 0;
    if (u < 0.3) {  // poster: A1..A3 or a custom size, portrait or landscape
      kind = 0;
      const int size = rng.Int(0, 3);
      w = size == 0 ? 0.594 : size == 1 ? 0.42 : size == 2 ? 0.297 : rng.Uniform(0.3, 0.9);
      h = size == 3 ? rng.Uniform(0.3, 0.9) : w * 1.414;
      if (rng.Chance(0.3)) std::swap(w, h);
      y = rng.Uniform(1.35, 1.7) - h / 2;
    } else if (u < 0.45) {
      kind = 1;
      w = rng.Uniform(0.6, 1.8);
      h = rng.Uniform(0.5, 1.0);
      y = rng.Uniform(0.95, 1.2);
    } else if (u < 0.62) {
      kind = 2;
      w = rng.Uniform(0.3, 1.0);
      h = rng.Uniform(0.25, 0.8);
      y = rng.Uniform(1.4, 1.75) - h / 2;
    } else if (u < 0.7) {
      kind = 3;
      w = rng.Uniform(0.9, 1.8);
      h = rng.Uniform(0.6, 1.0);
      y = rng.Uniform(0.9, 1.1);
    } else if (u < 0.8) {
      kind = 4;
      w = rng.Uniform(0.15, 0.4);
      h = rng.Uniform(0.08, 0.25);
      y = rng.Uniform(1.4, 1.9);
    } else if (u < 0.9) {
      kind = 5;
      w = 0.35;  // at most (clock)
    } else {     // a few leaflets taped straight onto the plaster
      kind = 6;
      w = rng.Uniform(0.25, 0.7);
      h = rng.Uniform(0.25, 0.45);
      y = rng.Uniform(1.1, 1.5);
    }
    if (x + w > end) {
      if (kind > 3 || end - x < 0.3) break;
      w = end - x;  // shrink boards and posters to the room left
    }
    y = std::min(y, top_limit - h);
    const cv::Rect r = cv.R(x, y, w, h);
    switch (kind) {
      case 0:
        DrawPoster(cv, r, rng);
        break;
      case 1:
        DrawNoticeBoard(cv, r, rng);
        break;
      case 2:
        DrawFramedPicture(cv, r, rng);
        break;
      case 3:
        DrawWhiteboard(cv, r, rng);
        break;
      case 4:
        DrawSign(cv, r, rng);
        break;
      case 5:
        w = DrawSmallFixture(cv, x, rng);
        break;
      default: {
        const int n = rng.Int(2, 4);
        for (int i = 0; i < n; ++i) {
          const double lw = rng.Uniform(0.15, 0.3);
          const double lh = rng.Uniform(0.15, 0.3);
          const double lx = x + rng.Uniform(0.0, std::max(0.0, w - lw));
          const double ly = y + rng.Uniform(0.0, std::max(0.0, h - lh));
          const cv::Rect lr = cv.R(lx, ly, lw, lh);
          DrawPoster(cv, lr, rng);
          // Tape at the top corners.
          const Colour tape = Grey(rng.Uniform(200.0, 235.0));
          Fill(cv, cv.R(lx - 0.01, ly + lh - 0.012, 0.04, 0.02), tape);
          Fill(cv, cv.R(lx + lw - 0.03, ly + lh - 0.012, 0.04, 0.02), tape);
        }
        break;
      }
    }
    x += w + rng.Uniform(0.05, 0.6) * inv;
  }
  // High up, above the door heads.
  x = a_m + rng.Uniform(0.05, 1.0) * std::min(inv, 3.0);
  while (x < b_m - 0.15) {
    const double used = DrawHighFixture(cv, x, 2.0, b_m - 0.05 - x, rng);
    x += used + rng.Uniform(0.5, 2.5) * inv;
  }
  // Low down.
  x = a_m + rng.Uniform(0.1, 1.0) * std::min(inv, 3.0);
  while (x < end - 0.15) {
    const double u = rng.Uniform();
    double w = 0.0;
    if (u < 0.4) {
      w = rng.Uniform(0.5, 1.6);
      if (x + w > end) w = end - x;
      if (w < 0.4) break;
      const double y = rng.Uniform(0.12, 0.2);
      const double h = rng.Uniform(0.35, 0.6);
      DrawRadiator(cv, x, y, w, h, rng);
    } else if (u < 0.6) {
      w = 0.22;
      if (x + w > end) break;
      DrawExtinguisher(cv, x, rng.Uniform(0.08, 0.25), rng);
    } else {
      w = 0.18;
      if (x + w > end) break;
      DrawPlate(cv, x, rng.Uniform(0.25, 0.4), true, rng);
    }
    x += w + rng.Uniform(0.4, 1.8) * inv;
  }
}

// ---------------------------------------------------------------------------------------------
// Walls.

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
  const int dots = static_cast<int>(std::lround(1.2 * area * density));
  for (int i = 0; i < dots; ++i) {
    const double x = rng.Uniform(0.0, width_m);
    const double y = rng.Uniform(0.3, cv.height_m);
    const double r = rng.Uniform(0.0015, 0.005);
    const double v = rng.Uniform(90.0, 160.0);
    cv::circle(cv.img, cv.P(x, y), cv.L(r), S(Grey(v)), cv::FILLED);
  }
  // Pencil and pen strokes.
  const int strokes = static_cast<int>(std::lround(0.3 * area * density));
  for (int i = 0; i < strokes; ++i) {
    const double x = rng.Uniform(0.0, width_m);
    const double y = rng.Uniform(0.5, 1.9);
    const double len = rng.Uniform(0.02, 0.12);
    const double ang = rng.Uniform(0.0, 2 * M_PI);
    const double v = rng.Uniform(110.0, 160.0);
    cv::line(cv.img, cv.P(x, y), cv.P(x + len * std::cos(ang), y + len * std::sin(ang)), S(Grey(v)),
             1, cv::LINE_8);
  }
  // Scuffs near the floor: short dark strokes from chairs, trolleys and shoes.
  const int scuffs = static_cast<int>(std::lround(1.2 * width_m * density));
  for (int i = 0; i < scuffs; ++i) {
    const double x = rng.Uniform(0.0, width_m);
    const double y = rng.Uniform(0.02, 0.7);
    const double len = rng.Uniform(0.03, 0.3);
    const double ang = rng.Uniform(-0.3, 0.3);
    const double v = rng.Uniform(40.0, 120.0);
    const int t = rng.Int(1, 3);
    const float alpha = static_cast<float>(rng.Uniform(0.15, 0.5));
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
    cv::line(cv.img, cv.P(x, y), cv.P(x + len, y + rng.Uniform(-0.01, 0.01)), S(colour + Grey(v)),
             1, cv::LINE_8);
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
  Colour skirting =
      Grey(plain ? skirting_rng.Uniform(95.0, 130.0) : skirting_rng.Uniform(50.0, 95.0));
  if (!plain && skirting_rng.Chance(0.35))
    skirting = Scale(Colour(55, 80, 115), skirting_rng.Uniform(0.7, 1.2));
  DrawSkirting(cv, width_m, o.skirting_height_m, skirting, skirting_rng, !plain);

  // Doors: random gaps between frames (rich), or a mean spacing +-15 % (plain).
  Rng door_rng(rng.Fork());
  const DoorScheme scheme = RandomDoorScheme(door_rng, plain);
  const double fw = scheme.frame_w_m;
  const double door_h = std::min(door_rng.Uniform(2.0, 2.1), cv.height_m - fw - 0.12);
  std::vector<std::pair<double, double>> frames;  // [left, right] of each frame (metres)
  if (door_h > 1.2 && o.doors) {
    if (plain) {
      double centre = door_rng.Uniform(0.2, 1.0) * o.plain_door_spacing_m;
      while (true) {
        const double dw = door_rng.Uniform(0.85, 0.95);
        const double left = centre - dw / 2 - fw;
        if (left >= 0.05 && left + dw + 2 * fw <= width_m - 0.05)
          frames.push_back({left, left + dw + 2 * fw});
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
    // Rich walls: now and then a door of another kind (service door, replaced door).
    DoorScheme own = scheme;
    if (!plain && one.Chance(0.3)) {
      own = RandomDoorScheme(one, false);
      own.frame_w_m = fw;
    }
    DrawDoor(cv, f.first + fw, f.second - f.first - 2 * fw, door_h, own, one, !plain);
    if (!plain && one.Chance(std::min(1.0, 0.35 * density))) {  // exit sign over the door
      const double sw = one.Uniform(0.3, 0.42);
      const double sh = one.Uniform(0.1, 0.15);
      const double sy = door_h + fw + one.Uniform(0.04, 0.12);
      if (sy + sh < cv.height_m - 0.02) {
        cv::Rect r = cv.R((f.first + f.second - sw) / 2, sy, sw, sh);
        Fill(cv, r, Colour(70, 140, 20));
        cv::Mat3f m = View(cv, r);
        DrawText(m, cv::Rect(m.cols / 3, m.rows / 4, m.cols / 2, m.rows / 2), m.rows * 0.3,
                 Grey(245), one);
        cv::arrowedLine(m, cv::Point(m.cols / 4, m.rows / 2), cv::Point(m.cols / 12, m.rows / 2),
                        S(Grey(245)), std::max(1, m.rows / 10), cv::LINE_8, 0, 0.4);
      }
    }
  }
  if (density <= 0.0) return;
  // Objects between the doors.
  double a = 0.0;
  for (size_t i = 0; i <= frames.size(); ++i) {
    const double b = i < frames.size() ? frames[i].first : width_m;
    Rng seg(rng.Fork());
    FillWallSegment(cv, a, b, i > 0, i < frames.size(), density, o.poster_share, seg);
    if (i < frames.size()) a = frames[i].second;
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
    Fill(cv,
         cv::Rect(r.x + b, r.y + b, std::max(1, r.width - 2 * b), std::max(1, r.height - 2 * b)),
         Grey(254));
    s += lamp_len + rng.Uniform(2.2, 3.8);
  }
}

// Floor tiles with grout: every tile its own shade, mottle, directional streaks, chips, wear and
// maybe a chipped corner; heel marks, dirt, scratches and a few service plates across the tiles.
void PaintFloor(Canvas& cv, uint64_t seed, const TextureOptions& o) {
  Rng rng(DeriveSeed(seed, 41));
  const double w = cv.img.cols / cv.ppm, h = cv.img.rows / cv.ppm;
  const double hue = rng.Uniform(0.0, 360.0);
  const double sat = rng.Uniform(0.03, 0.15);
  const double base = rng.Uniform(115.0, 175.0);
  const double spread = rng.Uniform(18.0, 30.0);  // tile-to-tile shade variation
  const Colour grout = Hsv(hue, sat * 0.5, base * rng.Uniform(0.62, 0.8));
  cv.img.setTo(S(grout));
  const double tile = o.floor_tile_m;
  const int g = std::max(1, cv.L(o.grout_width_m, 0));
  const double ox = rng.Uniform(0.0, tile);
  const double oy = rng.Uniform(0.0, tile);
  const double density = o.detail_density;
  const int nx = static_cast<int>(std::ceil((w + ox) / tile));
  const int ny = static_cast<int>(std::ceil((h + oy) / tile));
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      Rng t(DeriveSeed(seed, 4100, i, j));
      const double tx = -ox + i * tile, ty = -oy + j * tile;
      const int c0 = cv.X(tx), c1 = cv.X(tx + tile), r0 = cv.Y(ty), r1 = cv.Y(ty + tile);
      const cv::Rect in(c0 + (g + 1) / 2, r0 + (g + 1) / 2, std::max(1, c1 - c0 - g),
                        std::max(1, r1 - r0 - g));
      if ((in & cv::Rect(0, 0, cv.img.cols, cv.img.rows)).empty()) continue;
      const double shade = base + t.Uniform(-spread, spread);
      const double tile_hue = hue + t.Uniform(-6.0, 6.0);
      const double tile_sat = sat * t.Uniform(0.7, 1.3);
      const Colour colour = Hsv(tile_hue, tile_sat, shade);
      Fill(cv, in, colour);
      // Mottle, then streaks along x or y (vinyl tiles are laid in either direction).
      const uint64_t mottle_seed = t.Fork();
      const double mottle_cell = t.Uniform(0.01, 0.03);
      const double mottle_amp = t.Uniform(4.0, 9.0);
      AddNoise(cv, in, mottle_seed, cv.ppm * mottle_cell, cv.ppm * mottle_cell,
               static_cast<float>(mottle_amp));
      const uint64_t streak_seed = t.Fork();
      const double along = t.Uniform(0.08, 0.3), across = t.Uniform(0.005, 0.015);
      const double streak_amp = t.Uniform(3.0, 9.0);
      const bool along_x = t.Chance(0.5);
      AddNoise(cv, in, streak_seed, cv.ppm * (along_x ? along : across),
               cv.ppm * (along_x ? across : along), static_cast<float>(streak_amp));
      // Chips of darker and lighter material.
      const int chips = static_cast<int>(t.Uniform(10.0, 40.0) * (tile / 0.5) * (tile / 0.5));
      for (int k = 0; k < chips; ++k) {
        const int x = in.x + t.Int(0, in.width - 1);
        const int y = in.y + t.Int(0, in.height - 1);
        const int r = cv.L(t.Uniform(0.002, 0.005));
        const double d = t.Chance(0.6) ? t.Uniform(-45.0, -20.0) : t.Uniform(15.0, 35.0);
        cv::circle(cv.img, cv::Point(x, y), r, S(colour + Grey(d)), cv::FILLED);
      }
      // Wear: a soft patch, lighter or darker.
      if (t.Chance(0.5)) {
        const cv::Point c = RandomPointIn(in, t);
        const double rx = t.Uniform(0.05, 0.2);
        const double ry = t.Uniform(0.03, 0.12);
        const cv::Size ax(cv.L(rx), cv.L(ry));
        const double ang = t.Uniform(0.0, 180.0);
        const double tone = t.Uniform(-25.0, 15.0);
        SoftBlob(cv, c, ax, ang, colour + Grey(tone), static_cast<float>(t.Uniform(0.2, 0.5)),
                 cv.L(0.02));
      }
      // Dirt along the edges, and now and then a chipped corner.
      Bevel(cv, in, 1, -6.f, 8.f);
      if (t.Chance(0.06 * density)) {
        const int s = cv.L(t.Uniform(0.015, 0.05), 2);
        const int corner = t.Int(0, 3);
        const cv::Point p = corner == 0   ? in.tl()
                            : corner == 1 ? cv::Point(in.br().x - 1, in.y)
                            : corner == 2 ? cv::Point(in.x, in.br().y - 1)
                                          : in.br() - cv::Point(1, 1);
        const int sx = corner % 2 == 0 ? s : -s, sy = corner < 2 ? s : -s;
        const int sy2 = static_cast<int>(sy * t.Uniform(0.4, 1.2));
        std::vector<cv::Point> tri = {p, p + cv::Point(sx, 0), p + cv::Point(0, sy2)};
        cv::fillConvexPoly(cv.img, tri, S(grout + Grey(10)));
      }
    }
  }
  const double area = w * h;
  // Service plates: brushed metal squares with four screws.
  const int plates = static_cast<int>(std::floor(0.05 * area * density + rng.Uniform()));
  for (int i = 0; i < plates; ++i) {
    const double s = rng.Uniform(0.12, 0.25);
    const double px = rng.Uniform(0.0, std::max(0.0, w - s));
    const double py = rng.Uniform(0.0, std::max(0.0, h - s));
    const cv::Rect r = cv.R(px, py, s, s);
    Fill(cv, r, Grey(rng.Uniform(150.0, 195.0)));
    AddNoise(cv, r, rng.Fork(), cv.ppm * 0.2, 1.0, 6.f, 3.f);
    Bevel(cv, r, cv.L(0.004), 25.f, 35.f);
    for (int k = 0; k < 4; ++k) {
      cv::circle(cv.img,
                 cv.P(px + (k % 2 == 0 ? 0.015 : s - 0.015), py + (k < 2 ? 0.015 : s - 0.015)),
                 cv.L(0.004), S(Grey(60)), cv::FILLED);
    }
  }
  // Heel marks: short dark curved strokes.
  const int heels = static_cast<int>(std::lround(1.5 * area * density));
  for (int i = 0; i < heels; ++i) {
    const double x0 = rng.Uniform(0.0, w);
    const double y0 = rng.Uniform(0.0, h);
    const cv::Point p0 = cv.P(x0, y0);
    const double len = rng.Uniform(0.02, 0.12);
    const double a0 = rng.Uniform(0.0, 2 * M_PI);
    const double bend = rng.Uniform(-0.8, 0.8);
    const int t = rng.Chance(0.8) ? 1 : 2;
    const cv::Point p1 = p0 + cv::Point(cv.L(len * std::cos(a0), 0), cv.L(len * std::sin(a0), 0));
    const cv::Point p2 =
        p1 + cv::Point(cv.L(len * std::cos(a0 + bend), 0), cv.L(len * std::sin(a0 + bend), 0));
    const cv::Rect box = cv::boundingRect(std::vector<cv::Point>{p0, p1, p2}) + cv::Size(1, 1);
    const int pad = t + 1;
    cv::Mat1f mask = cv::Mat1f::zeros(box.height + 2 * pad, box.width + 2 * pad);
    const cv::Point org(box.x - pad, box.y - pad);
    cv::polylines(mask, std::vector<cv::Point>{p0 - org, p1 - org, p2 - org}, false,
                  cv::Scalar(1.0), t, cv::LINE_AA);
    const double tone = rng.Uniform(15.0, 50.0);
    const double alpha = rng.Uniform(0.25, 0.6);
    Composite(cv, org, mask, Grey(tone), static_cast<float>(alpha));
  }
  // Dirt spots.
  const int dirt = static_cast<int>(std::lround(2.0 * area * density));
  for (int i = 0; i < dirt; ++i) {
    const double cx = rng.Uniform(0.0, w);
    const double cy = rng.Uniform(0.0, h);
    const cv::Point c = cv.P(cx, cy);
    const double rx = rng.Uniform(0.005, 0.04);
    const double ry = rng.Uniform(0.005, 0.03);
    const cv::Size ax(cv.L(rx), cv.L(ry));
    const double ang = rng.Uniform(0.0, 180.0);
    SoftBlob(cv, c, ax, ang, Colour(60, 80, 95), static_cast<float>(rng.Uniform(0.15, 0.45)),
             cv.L(0.005));
  }
  // Long faint scratches.
  const int scratches = static_cast<int>(std::lround(1.0 * area * density));
  for (int i = 0; i < scratches; ++i) {
    const double x0 = rng.Uniform(0.0, w);
    const double y0 = rng.Uniform(0.0, h);
    const cv::Point p0 = cv.P(x0, y0);
    const double len = rng.Uniform(0.1, 0.5);
    const double a = rng.Uniform(0.0, 2 * M_PI);
    const double tone = rng.Uniform(-30.0, 30.0);
    const cv::Point p1 = p0 + cv::Point(cv.L(len * std::cos(a), 0), cv.L(len * std::sin(a), 0));
    const cv::Rect box = cv::boundingRect(std::vector<cv::Point>{p0, p1}) + cv::Size(1, 1);
    cv::Mat1f mask = cv::Mat1f::zeros(box.height + 2, box.width + 2);
    const cv::Point org(box.x - 1, box.y - 1);
    cv::line(mask, p0 - org, p1 - org, cv::Scalar(1.0), 1, cv::LINE_8);
    Composite(cv, org, mask, Grey(base + tone), 0.35f);
  }
}

// One light fixture over r (texels): a frame and an opal diffuser, a pair of lamps behind a
// prismatic cover, or an LED panel.
void DrawCeilingLight(Canvas& cv, const cv::Rect& r, bool along_x, Rng& rng) {
  const int kind = rng.Int(0, 2);
  Fill(cv, r, Grey(rng.Uniform(215.0, 235.0)));
  Bevel(cv, r, std::max(1, cv.L(0.006)), 12.f, 25.f);
  const int f = cv.L(rng.Uniform(0.02, 0.05));
  const cv::Rect in(r.x + f, r.y + f, std::max(1, r.width - 2 * f), std::max(1, r.height - 2 * f));
  if (kind == 0) {
    Fill(cv, in, Grey(rng.Uniform(246.0, 252.0)));
    Bevel(cv, in, 1, -20.f, -15.f);
  } else if (kind == 1) {
    Fill(cv, in, Grey(rng.Uniform(228.0, 240.0)));
    const int lamps = rng.Int(2, 3);
    for (int k = 0; k < lamps; ++k) {
      const double t = (k + 0.5) / lamps;
      const int bw = std::max(1, cv.L(0.035));
      const cv::Rect lamp =
          along_x ? cv::Rect(in.x, in.y + static_cast<int>(t * in.height) - bw / 2, in.width, bw)
                  : cv::Rect(in.x + static_cast<int>(t * in.width) - bw / 2, in.y, bw, in.height);
      Fill(cv, lamp, Grey(255));
    }
    Bevel(cv, in, 1, -25.f, -15.f);
  } else {
    Fill(cv, in, Grey(252));
    cv::circle(cv.img, cv::Point(in.x + in.width / 8, in.y + in.height / 2),
               std::max(1, cv.L(0.006)), S(Colour(60, 190, 60)), cv::FILLED);
  }
}

// A square supply-air diffuser over r: nested rings of louvres round a dark core.
void DrawVent(Canvas& cv, const cv::Rect& r, Rng& rng) {
  const Colour metal = Grey(rng.Uniform(215.0, 240.0));
  Fill(cv, r, metal);
  const int rings = rng.Int(2, 4);
  const int step = std::max(2, std::min(r.width, r.height) / (2 * rings + 3));
  for (int k = 1; k <= rings; ++k) {
    const cv::Rect ring(r.x + k * step, r.y + k * step, r.width - 2 * k * step,
                        r.height - 2 * k * step);
    if (ring.width < 2 || ring.height < 2) break;
    cv::rectangle(cv.img, ring, S(Grey(rng.Uniform(70.0, 130.0))), std::max(1, step / 3));
  }
  const int core = (rings + 1) * step;
  Fill(cv,
       cv::Rect(r.x + core, r.y + core, std::max(1, r.width - 2 * core),
                std::max(1, r.height - 2 * core)),
       Grey(rng.Uniform(50.0, 90.0)));
  Bevel(cv, r, 1, 15.f, 30.f);
}

// Suspended ceiling: panels on a T-bar grid, each panel its own shade, pinholes, fissures and
// maybe a stain; lights (one or two cells) and vents in irregular cells; sprinklers and smoke
// detectors on random panels.
void PaintCeiling(Canvas& cv, uint64_t seed, const TextureOptions& o) {
  Rng rng(DeriveSeed(seed, 51));
  const double w = cv.img.cols / cv.ppm, h = cv.img.rows / cv.ppm;
  const bool along_x = w >= h;  // lights are long along the longer side
  const double base = rng.Uniform(212.0, 236.0);
  const double hue = rng.Uniform(30.0, 60.0);
  const double density = o.detail_density;
  cv.img.setTo(S(Grey(std::min(250.0, base + rng.Uniform(4.0, 14.0)))));  // T-bar flanges
  const double panel = o.ceiling_panel_m;
  const int bar = std::max(1, cv.L(o.ceiling_grid_width_m, 0));
  const double ox = rng.Uniform(0.0, panel);
  const double oy = rng.Uniform(0.0, panel);
  const int nx = static_cast<int>(std::ceil((w + ox) / panel));
  const int ny = static_cast<int>(std::ceil((h + oy) / panel));
  auto cell_rect = [&](int i, int j, int si, int sj) {
    const int c0 = cv.X(-ox + i * panel), c1 = cv.X(-ox + (i + si) * panel);
    const int r0 = cv.Y(-oy + j * panel), r1 = cv.Y(-oy + (j + sj) * panel);
    return cv::Rect(c0 + (bar + 1) / 2, r0 + (bar + 1) / 2, std::max(1, c1 - c0 - bar),
                    std::max(1, r1 - r0 - bar));
  };
  // Which cells hold a light (1), the second cell of a light (2) or a vent (3).
  std::vector<int> use(static_cast<size_t>(nx) * ny, 0);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      if (use[j * nx + i] != 0) continue;
      const double u = rng.Uniform();
      if (u < 0.08 * std::min(density, 3.0)) {
        use[j * nx + i] = 1;
        const bool twin = rng.Chance(0.45);
        const int ti = along_x ? i + 1 : i, tj = along_x ? j : j + 1;
        if (twin && ti < nx && tj < ny && use[tj * nx + ti] == 0) use[tj * nx + ti] = 2;
      } else if (u < 0.105 * std::min(density, 3.0)) {
        use[j * nx + i] = 3;
      }
    }
  }
  // The grid's shadow side: one darker texel line on the flanges (lights cover it).
  for (int i = 0; i <= nx; ++i)
    Shift(cv, cv::Rect(cv.X(-ox + i * panel) - bar / 2, 0, 1, cv.img.rows), Grey(-12));
  for (int j = 0; j <= ny; ++j)
    Shift(cv, cv::Rect(0, cv.Y(-oy + j * panel) - bar / 2, cv.img.cols, 1), Grey(-12));
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      Rng t(DeriveSeed(seed, 5100, i, j));
      const cv::Rect in = cell_rect(i, j, 1, 1);
      if ((in & cv::Rect(0, 0, cv.img.cols, cv.img.rows)).empty()) continue;
      const int kind = use[j * nx + i];
      if (kind == 2) continue;  // painted with its light
      if (kind == 1) {
        const bool twin = along_x ? (i + 1 < nx && use[j * nx + i + 1] == 2)
                                  : (j + 1 < ny && use[(j + 1) * nx + i] == 2);
        DrawCeilingLight(cv, cell_rect(i, j, twin && along_x ? 2 : 1, twin && !along_x ? 2 : 1),
                         along_x, t);
        continue;
      }
      if (kind == 3) {
        const int m = std::max(1, in.width / 12);
        Fill(cv, in, Grey(base));
        DrawVent(cv,
                 cv::Rect(in.x + m, in.y + m, std::max(2, in.width - 2 * m),
                          std::max(2, in.height - 2 * m)),
                 t);
        continue;
      }
      // A mineral-fibre panel.
      const double shade = base + t.Uniform(-7.0, 7.0);
      const Colour colour = Hsv(hue, t.Uniform(0.0, 0.05), shade);
      Fill(cv, in, colour);
      const uint64_t ns = t.Fork();
      AddNoise(cv, in, ns, cv.ppm * 0.012, cv.ppm * 0.012, static_cast<float>(t.Uniform(2.0, 5.0)),
               2.f);
      const uint64_t sag = t.Fork();
      AddNoise(cv, in, sag, in.width * 0.6, in.height * 0.6,
               static_cast<float>(t.Uniform(2.0, 5.0)));
      const double area_m2 = in.area() / (cv.ppm * cv.ppm);
      const int pinholes = static_cast<int>(area_m2 * t.Uniform(150.0, 500.0));
      for (int k = 0; k < pinholes; ++k) {
        const int x = in.x + t.Int(0, in.width - 1);
        const int y = in.y + t.Int(0, in.height - 1);
        const double d = t.Uniform(-60.0, -25.0);
        if (x >= 0 && y >= 0 && x < cv.img.cols && y < cv.img.rows) cv.img(y, x) = colour + Grey(d);
      }
      const int fissures = static_cast<int>(area_m2 * t.Uniform(60.0, 200.0));
      for (int k = 0; k < fissures; ++k) {
        std::vector<cv::Point> pts = {RandomPointIn(in, t)};
        const int n = t.Int(1, 3);
        for (int q = 0; q < n; ++q) {
          const int dx = t.Int(-cv.L(0.012), cv.L(0.012));
          const int dy = t.Int(-cv.L(0.012), cv.L(0.012));
          pts.push_back(pts.back() + cv::Point(dx, dy));
        }
        const double d = t.Uniform(-45.0, -20.0);
        cv::Mat3f view = View(cv, in);
        for (auto& p : pts) p -= cv.Clip(in).tl();
        cv::polylines(view, pts, false, S(colour + Grey(d)), 1, cv::LINE_8);
      }
      if (t.Chance(0.05 * density)) {  // water stain: darker rim, lighter core
        const cv::Point c = RandomPointIn(in, t);
        const int rad = cv.L(t.Uniform(0.05, 0.2));
        SoftBlob(cv, c, cv::Size(rad, rad * 3 / 4 + 1), t.Uniform(0.0, 180.0),
                 Colour(120, 160, 185), 0.45f, cv.L(0.01));
        SoftBlob(cv, c, cv::Size(rad * 3 / 4 + 1, rad / 2 + 1), 0.0, colour + Colour(-10, -5, 0),
                 0.7f, cv.L(0.015));
      }
      // Tegular edge: a shadow line along the grid.
      Bevel(cv, in, 1, -18.f, 10.f);
      if (t.Chance(0.14 * density)) {  // sprinkler
        const cv::Point c = RandomPointIn(cv::Rect(in.x + in.width / 5, in.y + in.height / 5,
                                                   3 * in.width / 5 + 1, 3 * in.height / 5 + 1),
                                          t);
        cv::circle(cv.img, c, cv.L(0.025), S(Grey(t.Uniform(170.0, 215.0))), cv::FILLED);
        cv::circle(cv.img, c, cv.L(0.025), S(Grey(100)), 1);
        cv::circle(cv.img, c, cv.L(0.008), S(Grey(t.Uniform(40.0, 90.0))), cv::FILLED);
      } else if (t.Chance(0.05 * density)) {  // smoke detector
        const cv::Point c(in.x + in.width / 2 + t.Int(-in.width / 5, in.width / 5),
                          in.y + in.height / 2);
        cv::circle(cv.img, c + cv::Point(1, 1), cv.L(0.055), S(Grey(170)), cv::FILLED);
        cv::circle(cv.img, c, cv.L(0.055), S(Grey(244)), cv::FILLED);
        cv::circle(cv.img, c, cv.L(0.035), S(Grey(200)), 1);
        cv::circle(cv.img, c + cv::Point(cv.L(0.02), 0), std::max(1, cv.L(0.004)),
                   S(Colour(40, 40, 220)), cv::FILLED);
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
  } kKinds[] = {{"wall", TextureKind::kWall},
                {"floor", TextureKind::kFloor},
                {"ceiling", TextureKind::kCeiling},
                {"plainwall", TextureKind::kPlainWall},
                {"plainfloor", TextureKind::kPlainFloor},
                {"plainceiling", TextureKind::kPlainCeiling}};
  for (const auto& k : kKinds) {
    if (name == k.name) {
      *kind = k.kind;
      return true;
    }
  }
  return false;
}

bool ParseTextureName(const std::string& texture_name, TextureKind* kind, TextureOptions* options) {
  const size_t underscore = texture_name.find('_');
  if (underscore == std::string::npos) return false;
  const std::string prefix = texture_name.substr(0, underscore);
  size_t dash = prefix.find('-');
  TextureKind k;
  if (!ParseTextureKind(prefix.substr(0, dash), &k)) return false;
  TextureOptions o = *options;
  while (dash != std::string::npos) {
    const size_t next = prefix.find('-', dash + 1);
    const std::string style =
        prefix.substr(dash + 1, next == std::string::npos ? std::string::npos : next - dash - 1);
    if (style == "busy") {
      o.detail_density = 3.0;
    } else if (style == "bare") {
      o.detail_density = 0.0;
    } else if (style == "posters") {
      o.detail_density = 1.5;
      o.poster_share = 0.9;
    } else if (style == "furniture") {
      o.doors = false;
      o.skirting_height_m = 0.0;
    } else {
      return false;
    }
    dash = next;
  }
  *kind = k;
  *options = o;
  return true;
}

const char* TextureKindName(TextureKind kind) {
  switch (kind) {
    case TextureKind::kWall:
      return "wall";
    case TextureKind::kFloor:
      return "floor";
    case TextureKind::kCeiling:
      return "ceiling";
    case TextureKind::kPlainWall:
      return "plainwall";
    case TextureKind::kPlainFloor:
      return "plainfloor";
    case TextureKind::kPlainCeiling:
      return "plainceiling";
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
                 {"plain_grain_amplitude", plain_grain_amplitude, 0.0, false},
                 {"poster_share", poster_share, 0.0, false}};
  if (!(poster_share < 1.0)) return fail("poster_share must be < 1");
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
    return std::isfinite(px) && px >= 0.0 && px <= 4.0 * kMaxTextureSidePx ? static_cast<int>(px)
                                                                           : 0;
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
