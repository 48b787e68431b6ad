// Camera noise models applied to rendered grey images: exposure (gain and offset) and
// additive Gaussian pixel noise. Motion blur is made by the simulator, which averages renders
// over the exposure time (sim/simulator.h). Every draw comes from a seed: the same seed, frame
// and camera give the same noise.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "sim/scenario.h"

namespace sim {

// Applies gain, bias and pixel noise of `options` to `grey` (CV_32FC1, 0..255 scale) and
// returns the 8-bit image (saturated). `seed` should be derived from the scenario seed,
// the frame index and the camera index.
// The pixel noise is exactly that of SplitMix64::Normal() per pixel (the bytes are those of
// clamp(lround(gain * I + bias + pixel_sigma * Normal()))), computed faster (noise.cc).
cv::Mat ApplyCameraNoise(const cv::Mat& grey, const NoiseOptions& options, uint64_t seed);

// SplitMix64::BoxMuller(u1, u2) by polynomials, within ~1e-13 (the fast path of the pixel noise;
// exposed for its test).
double FastBoxMuller(double u1, double u2);

}  // namespace sim
