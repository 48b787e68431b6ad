#include "sim/data_dir.h"

#include <filesystem>
#include <system_error>

namespace sim {

namespace fs = std::filesystem;

std::string DataDirFor(const std::string& exe_path, const std::string& fallback) {
  if (!exe_path.empty()) {
    const fs::path share = fs::path(exe_path).parent_path().parent_path() / "share" / "vobench";
    std::error_code ec;
    if (fs::is_directory(share / "scenes", ec)) return share.lexically_normal().string();
  }
  return fallback;
}

const std::string& DataDir() {
  static const std::string dir = [] {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return DataDirFor(ec ? std::string() : exe.string(), VOBENCH_SOURCE_TREE);
  }();
  return dir;
}

}  // namespace sim
