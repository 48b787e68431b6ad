// Helpers for simulator tests: temporary scene folders with inline MJCF.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "sim/scenario.h"

namespace vobench_test {

// A fresh temporary folder, removed with the object.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("vobench_" + tag + "_" + (info ? std::string(info->name()) : "x") + "_" +
             std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

inline void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

// Writes `worldbody_xml` as a scene with the robot included into `dir` (robot_p2dx.xml is
// copied beside it: MuJoCo resolves includes relative to the main file). Returns its path.
inline std::string WriteScene(const TempDir& dir, const std::string& worldbody_xml,
                              const std::string& assets_xml = "") {
  std::filesystem::copy_file(std::string(VOBENCH_SOURCE_DIR) + "/scenes/robot_p2dx.xml",
                             dir / "robot_p2dx.xml",
                             std::filesystem::copy_options::overwrite_existing);
  const std::string scene = dir / "scene.xml";
  WriteText(scene,
            "<mujoco model='test'>\n"
            "  <option timestep='0.002' integrator='implicit'/>\n"
            "  <statistic extent='1'/>\n"
            "  <visual><headlight active='0' ambient='0 0 0' diffuse='0 0 0' specular='0 0 0'/>"
            "<map znear='0.02' zfar='40'/></visual>\n"
            "  <asset>" +
                assets_xml +
                "</asset>\n"
                "  <include file='robot_p2dx.xml'/>\n"
                "  <worldbody>\n"
                "    <geom name='physics_floor' type='plane' size='0 0 1' group='3'/>\n" +
                worldbody_xml + "  </worldbody>\n</mujoco>\n");
  return scene;
}

// A noise-free scenario on `scene` driving from (0,0) to (x_end, 0).
inline sim::Scenario MakeScenario(const std::string& scene, double x_end = 1.0) {
  sim::Scenario s;
  s.name = "test";
  s.scene_path = scene;
  s.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(x_end, 0)};
  s.settle_s = 0.2;
  return s;
}

}  // namespace vobench_test
