#include "harness/vo_config.h"

#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "sim/yaml_input.h"

namespace harness {
namespace {

// One supported key: how to read it from a scalar and how to print it.
struct Entry {
  std::function<bool(const YAML::Node&, std::string*)> read;  // false + what was expected
  std::function<void(YAML::Emitter&)> write;
};

template <typename T>
Entry Number(T* field, T lo, T hi) {
  return {[field, lo, hi](const YAML::Node& n, std::string* why) {
            T v;
            try {
              v = n.as<T>();
            } catch (const YAML::Exception&) {
              *why = std::string("expected a ") + (std::is_integral<T>::value ? "integer" : "number") + ", got '" + n.Scalar() + "'";
              return false;
            }
            if (!std::isfinite(static_cast<double>(v)) || v < lo || v > hi) {
              std::ostringstream s;
              s << "expected a finite value in [" << lo << ", " << hi << "], got " << n.Scalar();
              *why = s.str();
              return false;
            }
            *field = v;
            return true;
          },
          [field](YAML::Emitter& e) { e << *field; }};
}

Entry Bool(bool* field) {
  return {[field](const YAML::Node& n, std::string* why) {
            try {
              *field = n.as<bool>();
              return true;
            } catch (const YAML::Exception&) {
              *why = "expected true or false, got '" + n.Scalar() + "'";
              return false;
            }
          },
          [field](YAML::Emitter& e) { e << *field; }};
}

Entry Matcher(vo::MatcherType* field) {
  return {[field](const YAML::Node& n, std::string* why) {
            if (vo::ParseMatcherType(n.Scalar(), field)) return true;
            *why = "expected one of svd_proximity, svd_ncc, svd_ncc_gabor, ncc_mutual, lucas_kanade, kalman, sift_ratio; got '" + n.Scalar() + "'";
            return false;
          },
          [field](YAML::Emitter& e) { e << vo::ToString(*field); }};
}

Entry Prediction(vo::PredictionMode* field) {
  return {[field](const YAML::Node& n, std::string* why) {
            if (vo::ParsePredictionMode(n.Scalar(), field)) return true;
            *why = "expected none or motion_prior, got '" + n.Scalar() + "'";
            return false;
          },
          [field](YAML::Emitter& e) { e << vo::ToString(*field); }};
}

Entry DisparityModeEntry(vo::DisparityMode* field) {
  return {[field](const YAML::Node& n, std::string* why) {
            if (vo::ParseDisparityMode(n.Scalar(), field)) return true;
            *why = "expected dense or at_features, got '" + n.Scalar() + "'";
            return false;
          },
          [field](YAML::Emitter& e) { e << vo::ToString(*field); }};
}

Entry BaSolverEntry(vo::BaSolver* field) {
  return {[field](const YAML::Node& n, std::string* why) {
            for (vo::BaSolver a : {vo::BaSolver::kCeres, vo::BaSolver::kSchurLm}) {
              if (n.Scalar() == vo::ToString(a)) {
                *field = a;
                return true;
              }
            }
            *why = "expected ceres or schur_lm; got '" + n.Scalar() + "'";
            return false;
          },
          [field](YAML::Emitter& e) { e << vo::ToString(*field); }};
}

Entry DisparityAlgorithmEntry(vo::DisparityAlgorithm* field) {
  return {[field](const YAML::Node& n, std::string* why) {
            for (vo::DisparityAlgorithm a :
                 {vo::DisparityAlgorithm::kBlockMatching, vo::DisparityAlgorithm::kSemiGlobal,
                  vo::DisparityAlgorithm::kBlockMatchingOneVolume}) {
              if (n.Scalar() == vo::ToString(a)) {
                *field = a;
                return true;
              }
            }
            *why = "expected block_matching, block_matching_one_volume or semi_global; got '" +
                   n.Scalar() + "'";
            return false;
          },
          [field](YAML::Emitter& e) { e << vo::ToString(*field); }};
}

Entry Detector(vo::DetectorType* field) {
  return {[field](const YAML::Node& n, std::string* why) {
            if (n.Scalar() == "harris") *field = vo::DetectorType::kHarris;
            else if (n.Scalar() == "sift") *field = vo::DetectorType::kSift;
            else {
              *why = "expected harris or sift, got '" + n.Scalar() + "'";
              return false;
            }
            return true;
          },
          [field](YAML::Emitter& e) { e << (*field == vo::DetectorType::kHarris ? "harris" : "sift"); }};
}

Entry Wavelengths(std::vector<double>* field) {
  return {[field](const YAML::Node& n, std::string* why) {
            std::vector<double> v;
            try {
              if (!n.IsSequence()) throw YAML::Exception(n.Mark(), "");
              for (const auto& x : n) v.push_back(x.as<double>());
            } catch (const YAML::Exception&) {
              *why = "expected a list of wavelengths in pixels";
              return false;
            }
            for (double x : v)
              if (!(std::isfinite(x) && x >= 2.0 && x <= 64.0)) {
                *why = "expected wavelengths in [2, 64] pixels";
                return false;
              }
            if (v.empty()) {
              *why = "expected at least one wavelength";
              return false;
            }
            *field = v;
            return true;
          },
          [field](YAML::Emitter& e) {
            e << YAML::Flow << YAML::BeginSeq;
            for (double x : *field) e << x;
            e << YAML::EndSeq;
          }};
}

// The supported keys, in output order, bound to `o`'s fields.
std::vector<std::pair<std::string, Entry>> Registry(vo::OdometryOptions* o) {
  const double kInf = 1e12;
  return {
      {"detector.type", Detector(&o->detector.type)},
      {"detector.max_features", Number(&o->detector.max_features, 0, 100000)},
      {"detector.border_margin_px", Number(&o->detector.border_margin_px, 0, 1000)},
      {"detector.bucket_cols", Number(&o->detector.bucket_cols, 0, 1000)},
      {"detector.bucket_rows", Number(&o->detector.bucket_rows, 0, 1000)},
      {"detector.max_per_bucket", Number(&o->detector.max_per_bucket, 1, 100000)},
      {"detector.harris.quality_level", Number(&o->detector.harris.quality_level, 0.0, 0.999)},
      {"detector.harris.nms_radius_px", Number(&o->detector.harris.nms_radius_px, 1.0, 100.0)},
      {"detector.harris.k", Number(&o->detector.harris.k, 1e-6, 0.25)},
      {"disparity.algorithm", DisparityAlgorithmEntry(&o->disparity.algorithm)},
      {"disparity.block_size", Number(&o->disparity.block_size, 5, 255)},
      {"disparity.uniqueness_ratio", Number(&o->disparity.uniqueness_ratio, 0, 100)},
      {"disparity.left_right_max_diff_px", Number(&o->disparity.left_right_max_diff_px, -1.0, 1000.0)},
      {"disparity.min_texture", Number(&o->disparity.min_texture, 0.0, 1000.0)},
      {"disparity.speckle_window_size", Number(&o->disparity.speckle_window_size, 0, 100000)},
      {"disparity_min_depth_m", Number(&o->disparity_min_depth_m, 0.01, kInf)},
      {"disparity_mode", DisparityModeEntry(&o->disparity_mode)},
      {"disparity_range_from_scene", Bool(&o->disparity_range_from_scene)},
      {"disparity_range_margin", Number(&o->disparity_range_margin, 0.0, 100.0)},
      {"disparity_range_margin_px", Number(&o->disparity_range_margin_px, 0.0, 1000.0)},

      {"matcher.type", Matcher(&o->matcher.type)},
      {"matcher.prediction", Prediction(&o->matcher.prediction)},
      {"matcher.ncc.window_px", Number(&o->matcher.ncc.window_px, 3, 63)},
      {"matcher.gabor.wavelengths_px", Wavelengths(&o->matcher.gabor.wavelengths_px)},
      {"matcher.gabor.phase_exponent", Number(&o->matcher.gabor.phase_exponent, 0.0, 100.0)},
      {"matcher.svd.sigma_px", Number(&o->matcher.svd.sigma_px, 0.1, 1000.0)},
      {"matcher.svd.min_weight", Number(&o->matcher.svd.min_weight, 0.0, 1.0)},
      {"matcher.svd.min_pairing", Number(&o->matcher.svd.min_pairing, 0.0, 1.0)},
      {"matcher.svd.dense", Bool(&o->matcher.svd.dense)},
      {"matcher.ncc_mutual.search_radius_px", Number(&o->matcher.ncc_mutual.search_radius_px, 0.1, 10000.0)},
      {"matcher.ncc_mutual.min_score", Number(&o->matcher.ncc_mutual.min_score, 0.0, 1.0)},
      {"matcher.lucas_kanade.window_px", Number(&o->matcher.lucas_kanade.window_px, 5, 101)},
      {"matcher.lucas_kanade.max_level", Number(&o->matcher.lucas_kanade.max_level, 0, 8)},
      {"matcher.sift_ratio.ratio", Number(&o->matcher.sift_ratio.ratio, 0.01, 1.0)},
      {"ransac.inlier_threshold_px", Number(&o->ransac.inlier_threshold_px, 0.01, 1000.0)},
      {"ransac.confidence", Number(&o->ransac.confidence, 0.5, 0.999999)},
      {"ransac.max_iterations", Number(&o->ransac.max_iterations, 1, 100000)},
      {"ransac.seed", Number<uint64_t>(&o->ransac.seed, 0, UINT64_MAX)},
      {"use_bundle_adjustment", Bool(&o->use_bundle_adjustment)},
      {"ba_window_frames", Number(&o->ba_window_frames, 3, 10)},
      {"ba.max_num_iterations", Number(&o->ba.max_num_iterations, 1, 1000)},
      {"ba.loss_scale_px", Number(&o->ba.loss_scale_px, 0.01, 100.0)},
      {"ba.solver", BaSolverEntry(&o->ba.solver)},
      {"ba_max_points", Number(&o->ba_max_points, 0, 100000)},
      {"prior_weight", Number(&o->prior_weight, 0.0, 1.0)},
      {"estimate_initial_orientation", Bool(&o->estimate_initial_orientation)},
      {"adaptive_min_features", Number(&o->adaptive_min_features, 0, 100000)},
      {"adaptive_quality_level", Number(&o->adaptive_quality_level, 0.0, 0.999)},
      {"min_features", Number(&o->min_features, 0, 100000)},
      {"min_inliers", Number(&o->min_inliers, 3, 100000)},
      {"reinit_after_lost_frames", Number(&o->reinit_after_lost_frames, 1, 100000)},
      {"tracking.coarse_to_fine", Bool(&o->tracking.coarse_to_fine)},
      {"tracking.image_shift.min_score", Number(&o->tracking.image_shift.min_score, -1.0, 1.0)},
      {"tracking.image_shift.max_shift_fraction_x",
       Number(&o->tracking.image_shift.max_shift_fraction_x, 0.01, 0.9)},
      {"tracking.prior_radius_scale", Number(&o->tracking.prior_radius_scale, 0.05, 20.0)},
      {"tracking.shift_radius_scale", Number(&o->tracking.shift_radius_scale, 0.05, 20.0)},
      {"tracking.confident_min_inliers", Number(&o->tracking.confident_min_inliers, 0, 100000)},
      {"tracking.confident_inlier_fraction",
       Number(&o->tracking.confident_inlier_fraction, 0.0, 1.0)},
      {"tracking.guided_rematch", Bool(&o->tracking.guided_rematch)},
      {"tracking.guided_radius_scale", Number(&o->tracking.guided_radius_scale, 0.05, 20.0)},
      {"tracking.rotation_from_shift", Bool(&o->tracking.rotation_from_shift)},
      {"tracking.rotation_min_shift_score",
       Number(&o->tracking.rotation_min_shift_score, -1.0, 1.0)},
      {"tracking.rotation_min_peak_ratio",
       Number(&o->tracking.rotation_min_peak_ratio, 1.0, 1000.0)},
      {"tracking.rotation_min_residual_px",
       Number(&o->tracking.rotation_min_residual_px, 0.0, 1000.0)},
      {"tracking.reliable_min_inliers", Number(&o->tracking.reliable_min_inliers, 3, 100000)},
  };
}

// Walks the mapping; leaves (scalars and the wavelength list) are applied by dotted key.
// `seen` holds the line of every key applied so far: the same option given twice, once dotted
// and once nested ("matcher.type: a" and "matcher: {type: b}"), is a duplicate too.
bool Apply(const YAML::Node& node, const std::string& prefix, const std::string& source,
           std::map<std::string, Entry>& entries, std::map<std::string, int>* seen,
           std::string* error) {
  for (const auto& kv : node) {
    const std::string key = prefix.empty() ? kv.first.Scalar() : prefix + "." + kv.first.Scalar();
    const YAML::Node& v = kv.second;
    const int line = kv.first.Mark().line + 1;
    const std::string where = source + ":" + std::to_string(line) + ": key '" + key + "': ";
    auto it = entries.find(key);
    if (it != entries.end()) {
      const auto [first, inserted] = seen->emplace(key, line);
      if (!inserted) {
        *error = where + "duplicate (first at line " + std::to_string(first->second) + ")";
        return false;
      }
    }
    if (it == entries.end()) {
      if (v.IsMap()) {
        bool any = false;
        for (const auto& e : entries) any |= e.first.rfind(key + ".", 0) == 0;
        if (any) {
          if (!Apply(v, key, source, entries, seen, error)) return false;
          continue;
        }
      }
      *error = where + "unknown key (see `vobench run --help` and results' vo_options.yaml for the supported keys)";
      return false;
    }
    std::string why;
    if (!(v.IsScalar() || (v.IsSequence() && key == "matcher.gabor.wavelengths_px")) || !it->second.read(v, &why)) {
      *error = where + (why.empty() ? "expected a single value" : why);
      return false;
    }
  }
  return true;
}

}  // namespace

bool ParseVoConfig(const std::string& yaml_text, const std::string& source_name,
                   vo::OdometryOptions* options, std::string* error) {
  YAML::Node root;
  if (!sim::LoadYamlDocument(yaml_text, source_name, &root, error)) return false;
  if (root.IsNull()) return true;  // an empty file: defaults
  if (!root.IsMap()) {
    *error = source_name + ": expected a YAML mapping of VO options";
    return false;
  }
  vo::OdometryOptions o = *options;
  std::map<std::string, Entry> entries;
  for (auto& e : Registry(&o)) entries.emplace(e.first, e.second);
  std::map<std::string, int> seen;
  if (!Apply(root, "", source_name, entries, &seen, error)) return false;
  std::string why;
  if (!o.IsValid(&why)) {
    *error = source_name + ": invalid VO options: " + why;
    return false;
  }
  *options = o;
  return true;
}

bool LoadVoConfig(const std::string& path, vo::OdometryOptions* options, std::string* error) {
  std::string text;
  if (!sim::ReadInputFile(path, "YAML VO config file", &text, error)) return false;
  return ParseVoConfig(text, path, options, error);
}

std::string VoConfigToYaml(const vo::OdometryOptions& options) {
  vo::OdometryOptions o = options;
  // Nested output: group consecutive keys by their dotted prefixes.
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  std::vector<std::string> open;
  for (auto& [key, entry] : Registry(&o)) {
    std::vector<std::string> parts;
    std::stringstream ss(key);
    std::string p;
    while (std::getline(ss, p, '.')) parts.push_back(p);
    size_t common = 0;
    while (common < open.size() && common + 1 < parts.size() && open[common] == parts[common]) ++common;
    while (open.size() > common) {
      out << YAML::EndMap;
      open.pop_back();
    }
    for (size_t i = common; i + 1 < parts.size(); ++i) {
      out << YAML::Key << parts[i] << YAML::Value << YAML::BeginMap;
      open.push_back(parts[i]);
    }
    out << YAML::Key << parts.back() << YAML::Value;
    entry.write(out);
  }
  while (!open.empty()) {
    out << YAML::EndMap;
    open.pop_back();
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace harness
