// libviso2's stereo VO (VisualOdometryStereo, its default parameters) on a KITTI-layout folder,
// for measuring only (results/speed/viso2/measure.sh builds it against a fetched copy of the
// public source; it is no part of vobench's build). Reads image_0/ and image_1/ (%06d.png) and
// calib.txt (P0, P1: f, cu, cv, baseline = -P1[3] / P1[0]); writes OUT/poses.txt (KITTI: the
// camera's pose in the first camera's frame, 12 numbers per line) and OUT/times_ms.txt (the
// process() call of each frame, milliseconds, steady clock), and prints the median.
//   viso2_kitti DATASET OUT [MAX_FRAMES]
#include <viso_stereo.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

bool ReadCalib(const std::string& path, double* f, double* cu, double* cv, double* base) {
  std::ifstream in(path);
  std::string line;
  std::vector<double> p0, p1;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string key;
    s >> key;
    std::vector<double>* p = key == "P0:" ? &p0 : key == "P1:" ? &p1 : nullptr;
    if (p == nullptr) continue;
    double x;
    while (s >> x) p->push_back(x);
  }
  if (p0.size() != 12 || p1.size() != 12 || !(p0[0] > 0.0) || !(p1[0] > 0.0)) return false;
  *f = p0[0];
  *cu = p0[2];
  *cv = p0[6];
  *base = -p1[3] / p1[0];
  return *base > 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: viso2_kitti DATASET OUT [MAX_FRAMES]\n";
    return 2;
  }
  const std::string dir = argv[1], out = argv[2];
  const int max_frames = argc > 3 ? std::atoi(argv[3]) : 0;
  VisualOdometryStereo::parameters param;
  if (!ReadCalib(dir + "/calib.txt", &param.calib.f, &param.calib.cu, &param.calib.cv,
                 &param.base)) {
    std::cerr << dir << "/calib.txt: no P0/P1 with a positive baseline\n";
    return 1;
  }
  VisualOdometryStereo viso(param);
  Matrix pose = Matrix::eye(4);
  std::ofstream poses(out + "/poses.txt"), times(out + "/times_ms.txt");
  if (!poses || !times) {
    std::cerr << out << ": cannot write\n";
    return 1;
  }
  std::vector<double> ms;
  int failed = 0;
  for (int i = 0; max_frames <= 0 || i < max_frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "/%06d.png", i);
    if (!std::ifstream(dir + "/image_0" + name).good()) break;  // the end of the sequence
    cv::Mat left = cv::imread(dir + "/image_0" + name, cv::IMREAD_GRAYSCALE);
    cv::Mat right = cv::imread(dir + "/image_1" + name, cv::IMREAD_GRAYSCALE);
    if (left.empty() || right.empty()) break;
    if (!left.isContinuous()) left = left.clone();
    if (!right.isContinuous()) right = right.clone();
    int32_t dims[] = {left.cols, left.rows, left.cols};
    const auto t0 = std::chrono::steady_clock::now();
    const bool ok = viso.process(left.data, right.data, dims);
    const double t =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (ok) {
      pose = pose * Matrix::inv(viso.getMotion());
    } else if (i > 0) {
      ++failed;
    }
    if (i > 0) ms.push_back(t);  // the first call only stores the images
    times << t << "\n";
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) poses << pose.val[r][c] << (r == 2 && c == 3 ? "\n" : " ");
  }
  if (ms.empty()) {
    std::cerr << dir << ": fewer than two frames\n";
    return 1;
  }
  std::vector<double> sorted = ms;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  std::printf("frames %zu failed %d median_ms %.4f\n", ms.size() + 1, failed,
              sorted[sorted.size() / 2]);
  return 0;
}
