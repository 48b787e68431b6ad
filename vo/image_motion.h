// Dominant image motion between two grey frames: one global 2-D translation, estimated
// coarse-to-fine on an image pyramid ("multi-scale analysis when the motion prior is weak").
// A feature matcher can then search around uv_prev + shift_px instead of around uv_prev.
//
// Contract: shift_px = s such that curr(x + s) ≈ prev(x), in pixels of the full-resolution
// image, x right and y down. The score is the zero-mean normalised cross-correlation (ZNCC,
// Pearson ρ ∈ [−1, 1]) of prev and curr over their overlap at that shift, so a gain and offset
// change between the frames does not matter.
//
// Model: a pure translation of the whole image. Good for a camera rotating about its optical
// centre about the vertical (pan → dx) or horizontal (tilt → dy) axis, e.g. a robot turning in
// place (the true motion is a homography: off-centre pixels move slightly differently for a
// wide field of view); with camera translation, parallax makes it the dominant (area-weighted)
// motion only. Rotation about the optical axis and zoom are not modelled (the peak flattens).
//
// Method: both pyramids are built with cv::pyrDown until the level's width is
// <= coarsest_max_width_px. At the coarsest level every integer shift with
// |dx| <= max_shift_fraction_x · width, |dy| <= max_shift_fraction_y · height and overlap
// >= min_overlap_fraction of the area is scored (exhaustive: no prior needed); the best wins
// (ties: smaller dx² + dy², then smaller dx, then smaller dy). Each finer level searches
// ±refine_radius_px around twice the coarser estimate (re-centred, at most a few times, while
// the best lies on the window border); at finest_level an optional parabolic fit through the
// best score and its x and y neighbours gives the sub-pixel part (each axis separately).
// Sums are exact integers, the ZNCC is double: results are deterministic and bit-identical
// between calls.
//
// Cost: per level, one pass over each image (sums of v and v² at the few column boundaries the
// overlaps need), plus one integer dot product over the overlap per scored shift: at the
// coarsest level (2·⌊0.45·w⌋ + 1)·(2·⌊0.25·h⌋ + 1) shifts (555 at 40×30), at each finer level
// (2r + 1)² = 25; the full-resolution dot products dominate. Measured (median of 50 calls, one
// core of an AMD EPYC, -O2, cv::setNumThreads(1)): ~0.4–0.5 ms at 320×240, ~1.2–1.8 ms at
// 640×480 (-O3: ~10 % slower). No threads of its own (cv::pyrDown may use OpenCV's pool;
// results do not depend on it). Memory: the pyramids plus O(w + h) per level.
//
// Failure modes: textureless images (no shift scored: ok = false, "no texture"); periodic
// texture (several equal peaks: see second_best_ratio ≈ 1; the pick among them is arbitrary);
// texture constant along one direction (that component is arbitrary); texture finer than the
// coarsest level resolves (it vanishes in the pyramid); strong parallax or independently moving
// objects covering most of the image (the dominant motion may not be the camera's).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>

namespace vo {

struct ImageShiftOptions {
  int coarsest_max_width_px = 48;      // the pyramid (cv::pyrDown) is reduced until the level's
                                       // width is <= this (pixels); >= 16
  double max_shift_fraction_x = 0.45;  // exhaustive search at the coarsest level over
                                       // |dx| <= this · width; in (0, 0.9]
  double max_shift_fraction_y = 0.25;  // and |dy| <= this · height; in [0, 0.9]
  int refine_radius_px = 2;  // at each finer level the search is ±this around twice the coarser
                             // estimate (pixels of that level); >= 1
  int finest_level = 0;      // stop refining at this pyramid level (0 = full resolution; clamped to
                             // the coarsest level); >= 0
  double min_overlap_fraction = 0.3;  // a shift is scored only if the overlap of the two images
                                      // is at least this fraction of the image area; in (0, 1]
  double min_score = 0.3;  // result ok only if the ZNCC at the finest level is >= this; [-1, 1]
  bool subpixel = true;    // parabolic sub-pixel refinement at the finest level

  bool IsValid(std::string* error) const;
};

struct ImageShiftResult {
  bool ok = false;                                     // a shift with score >= min_score was found
  std::string message;                                 // why not ok (empty when ok)
  Eigen::Vector2d shift_px = Eigen::Vector2d::Zero();  // curr(x + shift) ≈ prev(x) (pixels,
                                                       // full resolution); also filled when a
                                                       // shift was found but scored < min_score
  double score = -1.0;  // ZNCC at the best integer shift of the finest level searched (-1 when
                        // nothing could be scored)
  int levels = 0;       // pyramid levels built, including the full resolution (the search runs
                        // on levels min(finest_level, levels − 1) .. levels − 1)
  double second_best_ratio = 0.0;  // ambiguity at the coarsest level: best score / score of the
                                   // best other local maximum (8-neighbourhood) at Chebyshev
                                   // distance >= 2 from the best; +inf when there is no such
                                   // peak with a positive score, 1 when the best score is <= 0,
                                   // 0 when the coarsest level was not searched. ≈ 1 means
                                   // ambiguous (e.g. periodic texture)
};

// Dominant translation of the image content from `prev` to `curr` (both CV_8UC1, same size,
// at least 8×8 pixels; ROIs are fine). Bad input (empty, wrong type, different sizes, too
// small, invalid options) gives ok = false with a message naming the problem, never a crash.
ImageShiftResult EstimateImageShift(const cv::Mat& prev, const cv::Mat& curr,
                                    const ImageShiftOptions& options = ImageShiftOptions());

}  // namespace vo
