// Helpers shared by the files of harness/dataset/ (the writer, the readers, rectification); not
// part of the dataset API (harness/dataset.h).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "harness/trajectory_io.h"
#include "vo/camera.h"

namespace harness::dataset_internal {

// Sets *error (when non-null) to `message`; returns false.
bool Fail(std::string* error, const std::string& message);
// "path:line: ", the start of a message about a line of a file.
std::string Where(const std::string& path, int line);
// a / b as a path.
std::string Join(const std::string& a, const std::string& b);
// "%06zu" of the frame index, then the extension: "000042.png".
std::string FrameName(size_t index, const char* extension);
// "WIDTHxHEIGHT" of an image.
std::string SizeText(const cv::Mat& m);
// The widest field of view an equidistant (fisheye) camera may claim (degrees, exclusive).
constexpr double kMaxFisheyeFovDeg = 240.0;
// A camera's intrinsics in the plausible ranges of every layout (KITTI, EuRoC, TUM, rig.yaml):
// horizontal and vertical fields of view from the focal lengths and the image size in (1, 170)
// degrees (a pinhole's 2 atan(w / 2f); `equidistant`: a fisheye's w / f, up to 240 degrees), the
// principal point inside the image. Empty when fine (or when the size is unknown, <= 0), else the
// problem.
std::string IntrinsicsProblem(int width, int height, double fx, double fy, double cx, double cy,
                              bool equidistant);
// A rig in the plausible ranges the simulator also keeps (sim/scenario.h): baseline 1 mm .. 5 m,
// and IntrinsicsProblem of its rectified camera (checked only when width and height are known).
// A value outside is refused rather than run into inf/NaN metrics. Empty when fine, else the
// problem.
std::string RigProblem(const vo::StereoCamera& c);
// R is finite, orthonormal to within `tolerance` (max |R^T R - I| entry) and has det > 0.
bool IsRotation(const Eigen::Matrix3d& R, double tolerance);
// Folder names without a trailing separator ("out/" -> "out"), so "DIR.partial-" is a sibling.
std::string NormalizeDir(const std::string& dir);
// EuRoC's nanosecond stamps in seconds.
double NsToSeconds(int64_t t_ns);

// --- The readers' common steps.

// Fails, naming `dir`, when `index` is not below `size` (the frames of the reader).
bool CheckFrameIndex(const std::string& dir, size_t index, size_t size, std::string* error);
// Reads one grey image of a stereo frame as 8 bits and checks its size against `expected`;
// `origin` says where the expected size comes from (e.g. "the size of frame 0"). Images by their
// bit depth: `bits` is the sequence's (FirstPairBits): 8 for 8-bit images (colour converted to
// grey), else the bits its 16-bit images use (10, 12, 14, 16), mapped to 8 bits as
// value >> (bits - 8) for every frame alike; a value beyond that range, or an image of the other
// depth, is refused with the reason. Error names the file.
bool ReadGreyImage(const std::string& path, const cv::Size& expected, const std::string& origin,
                   int bits, cv::Mat* image, std::string* error);
// The bit depth of a sequence from its first pair: 8 for 8-bit images; for 16-bit ones the
// largest value of the pair rounded up to 8, 10, 12, 14 or 16 bits (so 8-bit values stored in 16
// bits, a 12-bit sensor's LSB-aligned data and full-range 16-bit data all read right).
bool FirstPairBits(const std::string& left_path, const std::string& right_path, int* bits,
                   std::string* error);
// The image size of a layout whose calibration (calib_path) has none: reads the first pair,
// which must decode and agree in size, sets camera->width and height and *bits
// (FirstPairBits), and checks the camera (vo::StereoCamera::IsValid, RigProblem). Errors name
// the image files or calib_path.
bool TakeImageSizeFromFirstPair(const std::string& left_path, const std::string& right_path,
                                const std::string& calib_path, vo::StereoCamera* camera, int* bits,
                                std::string* error);
// Frames with an associated ground-truth pose (index >= 0).
size_t CountAssociated(const std::vector<long>& index);
// *index = AssociateGroundTruth(frame_s, gt, max_difference_s); fails when no frame has a pose
// (different clocks, wrong file), naming gt_path and the two time ranges.
bool AssociateWithFrames(const std::string& gt_path, const std::vector<double>& frame_s,
                         const std::vector<StampedPose>& gt, double max_difference_s,
                         std::vector<long>* index, std::string* error);

}  // namespace harness::dataset_internal
