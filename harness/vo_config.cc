#include "harness/vo_config.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cmath>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <map>
#include <sstream>
#include <type_traits>
#include <utility>
#include <vector>

#include "sim/yaml_input.h"

namespace harness {
namespace {

using sim::YamlReader;

// One supported key: how to read its value (failing through the reader, which names the file,
// the line and the key) and how to print it.
struct Entry {
  std::function<bool(YamlReader&, const YAML::Node&, const std::string&)> read;
  std::function<void(YAML::Emitter&)> write;
  bool sequence = false;  // the value is a YAML list (else a scalar)
};

template <typename T>
Entry Number(T* field, T lo, T hi) {
  return {[field, lo, hi](YamlReader& r, const YAML::Node& n, const std::string& key) {
            if constexpr (std::is_same_v<T, uint64_t>) {
              return r.ReadUint64(n, key, field);  // [lo, hi] is the whole of uint64_t
            } else if constexpr (std::is_integral_v<T>) {
              return r.ReadInt(n, key, lo, hi, field);
            } else {
              return r.ReadDoubleIn(n, key, lo, hi, field);
            }
          },
          [field](YAML::Emitter& e) { e << *field; }};
}

Entry Bool(bool* field) {
  return {[field](YamlReader& r, const YAML::Node& n, const std::string& key) {
            return r.ReadBool(n, key, field);
          },
          [field](YAML::Emitter& e) { e << *field; }};
}

// An enum by its vo::ToString names (the name tables live in vo/).
template <typename E>
Entry Enum(E* field, std::initializer_list<E> values) {
  std::vector<std::pair<std::string, E>> table;
  for (E v : values) table.emplace_back(vo::ToString(v), v);
  return {[field, table](YamlReader& r, const YAML::Node& n, const std::string& key) {
            return r.ReadEnum(n, key, table, field);
          },
          [field](YAML::Emitter& e) { e << vo::ToString(*field); }};
}

// A 3-vector as a list [x, y, z] of finite numbers.
Entry Vector3(Eigen::Vector3d* field) {
  Entry entry{[field](YamlReader& r, const YAML::Node& n, const std::string& key) {
                std::vector<double> v;
                if (!r.ReadNumbers(n, key, 3, &v, "a list of 3 numbers [x, y, z]")) return false;
                *field = Eigen::Vector3d(v[0], v[1], v[2]);
                return true;
              },
              [field](YAML::Emitter& e) {
                e << YAML::Flow << YAML::BeginSeq << field->x() << field->y() << field->z()
                  << YAML::EndSeq;
              }};
  entry.sequence = true;
  return entry;
}

Entry Wavelengths(std::vector<double>* field) {
  Entry entry{[field](YamlReader& r, const YAML::Node& n, const std::string& key) {
                std::vector<double> v;
                if (!r.ReadNumbers(n, key, 0, &v, "a list of wavelengths in pixels")) return false;
                for (double x : v)
                  if (!(x >= 2.0 && x <= 64.0))
                    return r.Fail(n, key, "expected wavelengths in [2, 64] pixels");
                if (v.empty()) return r.Fail(n, key, "expected at least one wavelength");
                *field = v;
                return true;
              },
              [field](YAML::Emitter& e) {
                e << YAML::Flow << YAML::BeginSeq;
                for (double x : *field) e << x;
                e << YAML::EndSeq;
              }};
  entry.sequence = true;
  return entry;
}

// The supported keys, in output order, bound to `o`'s fields: every field of
// vo::OdometryOptions and its nested Options structs (tests/harness/vo_config_test.cc fails
// when a struct grows a field that is not listed here). Ranges are what YAML may hold; each
// Options::IsValid checks the finer rules after reading.
// The keys of a direct alignment's options (recovery.vehicle_direct, recovery.free_direct).
std::vector<std::pair<std::string, Entry>> DirectAlignmentKeys(const std::string& prefix,
                                                               bool* enabled,
                                                               vo::DirectAlignmentOptions* d) {
  return {
      {prefix + ".enabled", Bool(enabled)},
      {prefix + ".pyramid_levels", Number(&d->pyramid_levels, 1, 6)},
      {prefix + ".min_gradient", Number(&d->min_gradient, 1e-6, 1000.0)},
      {prefix + ".max_pixels", Number(&d->max_pixels, 1, 10000000)},
      {prefix + ".max_iterations", Number(&d->max_iterations, 1, 100000)},
      {prefix + ".huber_k", Number(&d->huber_k, 1e-6, 1000.0)},
      {prefix + ".tukey_k", Number(&d->tukey_k, 0.0, 1000.0)},
      {prefix + ".min_pixels", Number(&d->min_pixels, 1, 10000000)},
      {prefix + ".max_yaw_sigma_deg", Number(&d->max_yaw_sigma_deg, 1e-9, 180.0)},
      {prefix + ".max_forward_sigma_m", Number(&d->max_forward_sigma_m, 1e-9, 100.0)},
      {prefix + ".max_yaw_change_deg", Number(&d->max_yaw_change_deg, 1e-9, 180.0)},
      {prefix + ".max_forward_change_m", Number(&d->max_forward_change_m, 1e-9, 100.0)},
      {prefix + ".min_depth_m", Number(&d->min_depth_m, 1e-9, 1e6)},
      {prefix + ".max_depth_m", Number(&d->max_depth_m, 1e-9, 1e6)},
  };
}

std::vector<std::pair<std::string, Entry>> Registry(vo::OdometryOptions* o) {
  const double kInf = 1e12;
  const int kBig = 100000000;
  vo::FrontEndOptions& fe = o->front_end;
  vo::DetectorOptions& d = fe.detector;
  vo::DisparityOptions& disp = fe.disparity;
  vo::InitialOrientationOptions& io = o->initial_orientation;
  vo::PlaneOrientationOptions& po = io.planes;
  vo::PlaneRefinementOptions& fr = io.floor_refinement;
  vo::TrackerOptions& t = o->tracker;
  vo::MatcherOptions& m = t.matcher;
  vo::MotionOptions& mo = o->motion;
  vo::RansacOptions& r = mo.ransac;
  vo::RecoveryOptions& rc = o->recovery;
  vo::BundleAdjustmentOptions& ba = o->back_end.ba;
  using vo::BaLinearSolver;
  using vo::BaSolver;
  using vo::DisparityAlgorithm;
  using vo::RobustLoss;
  std::vector<std::pair<std::string, Entry>> keys = {
      {"platform", Enum(&o->platform,
                        {vo::Platform::kAuto, vo::Platform::kFree, vo::Platform::kGroundVehicle})},
      {"vehicle.enabled", Bool(&mo.ground_vehicle)},
      {"vehicle.no_sideways_slip", Bool(&mo.few_point.no_sideways_slip)},
      {"vehicle.axle_behind_camera_m", Number(&mo.few_point.axle_behind_camera_m, -10.0, 10.0)},
      {"front_end.detector.type",
       Enum(&d.type, {vo::DetectorType::kHarris, vo::DetectorType::kSift})},
      {"front_end.detector.max_features", Number(&d.max_features, 0, 100000)},
      {"front_end.detector.border_margin_px", Number(&d.border_margin_px, 0, 1000)},
      {"front_end.detector.bucket_cols", Number(&d.bucket_cols, 0, 1000)},
      {"front_end.detector.bucket_rows", Number(&d.bucket_rows, 0, 1000)},
      {"front_end.detector.max_per_bucket", Number(&d.max_per_bucket, 1, 100000)},
      {"front_end.detector.harris.block_size", Number(&d.harris.block_size, 1, 255)},
      {"front_end.detector.harris.aperture_size", Number(&d.harris.aperture_size, 1, 31)},
      {"front_end.detector.harris.k", Number(&d.harris.k, 1e-6, 0.25)},
      {"front_end.detector.harris.quality_level", Number(&d.harris.quality_level, 0.0, 0.999)},
      {"front_end.detector.harris.min_response", Number(&d.harris.min_response, 0.0, kInf)},
      {"front_end.detector.harris.nms_radius_px", Number(&d.harris.nms_radius_px, 1.0, 100.0)},
      {"front_end.detector.harris.subpixel", Bool(&d.harris.subpixel)},
      {"front_end.detector.harris.subpixel_half_window_px",
       Number(&d.harris.subpixel_half_window_px, 1, 100)},
      {"front_end.detector.harris.subpixel_max_iterations",
       Number(&d.harris.subpixel_max_iterations, 1, 10000)},
      {"front_end.detector.harris.subpixel_epsilon_px",
       Number(&d.harris.subpixel_epsilon_px, 0.0, 10.0)},
      {"front_end.detector.sift.octave_layers", Number(&d.sift.octave_layers, 1, 20)},
      {"front_end.detector.sift.contrast_threshold", Number(&d.sift.contrast_threshold, 0.0, 1.0)},
      {"front_end.detector.sift.edge_threshold", Number(&d.sift.edge_threshold, 0.0, 1000.0)},
      {"front_end.detector.sift.sigma", Number(&d.sift.sigma, 0.01, 100.0)},
      {"front_end.detector.sift.unique_positions", Bool(&d.sift.unique_positions)},
      {"front_end.adaptive_min_features", Number(&fe.adaptive_min_features, 0, 100000)},
      {"front_end.adaptive_quality_level", Number(&fe.adaptive_quality_level, 0.0, 0.999)},
      {"front_end.disparity.algorithm",
       Enum(&disp.algorithm, {DisparityAlgorithm::kBlockMatching, DisparityAlgorithm::kSemiGlobal,
                              DisparityAlgorithm::kBlockMatchingOneVolume})},
      {"front_end.disparity.min_disparity_px", Number(&disp.min_disparity_px, 0, 10000)},
      {"front_end.disparity.num_disparities", Number(&disp.num_disparities, 16, 10000)},
      {"front_end.disparity.block_size", Number(&disp.block_size, 1, 255)},
      {"front_end.disparity.prefilter_cap", Number(&disp.prefilter_cap, 1, 63)},
      {"front_end.disparity.uniqueness_ratio", Number(&disp.uniqueness_ratio, 0, 100)},
      {"front_end.disparity.min_texture", Number(&disp.min_texture, 0.0, 1000.0)},
      {"front_end.disparity.left_right_max_diff_px",
       Number(&disp.left_right_max_diff_px, -1.0, 1000.0)},
      {"front_end.disparity.full_width", Bool(&disp.full_width)},
      {"front_end.disparity.speckle_window_size", Number(&disp.speckle_window_size, 0, 100000)},
      {"front_end.disparity.speckle_range_px", Number(&disp.speckle_range_px, 0.0, 1000.0)},
      {"front_end.disparity.sgbm_p1", Number(&disp.sgbm_p1, 0, kBig)},
      {"front_end.disparity.sgbm_p2", Number(&disp.sgbm_p2, 0, kBig)},
      {"front_end.disparity.sgbm_full_dp", Bool(&disp.sgbm_full_dp)},
      {"front_end.disparity_mode",
       Enum(&fe.disparity_mode, {vo::DisparityMode::kDense, vo::DisparityMode::kAtFeatures})},
      {"front_end.disparity_range_from_scene", Bool(&fe.disparity_range_from_scene)},
      {"front_end.disparity_range_margin", Number(&fe.disparity_range_margin, 0.0, 100.0)},
      {"front_end.disparity_range_margin_px", Number(&fe.disparity_range_margin_px, 0.0, 1000.0)},
      {"front_end.derive_num_disparities", Bool(&fe.derive_num_disparities)},
      {"front_end.disparity_min_depth_m", Number(&fe.disparity_min_depth_m, 0.01, kInf)},
      {"front_end.max_num_disparities", Number(&fe.max_num_disparities, 16, 10000)},
      {"front_end.depth.sampling", Enum(&fe.depth.sampling, {vo::DisparitySampling::kNearest,
                                                             vo::DisparitySampling::kBilinear})},
      {"front_end.depth.search_radius_px", Number(&fe.depth.search_radius_px, 0, 100)},
      {"front_end.depth.max_spread_px", Number(&fe.depth.max_spread_px, 0.0, 1000.0)},
      {"front_end.depth.min_depth_m", Number(&fe.depth.min_depth_m, 1e-6, kInf)},
      {"front_end.depth.max_depth_m", Number(&fe.depth.max_depth_m, 1e-6, kInf)},
      {"front_end.min_features", Number(&fe.min_features, 0, 100000)},
      {"initial_orientation.enabled", Bool(&io.enabled)},
      {"initial_orientation.planes.max_planes", Number(&po.max_planes, 1, 100)},
      {"initial_orientation.planes.min_plane_inliers", Number(&po.min_plane_inliers, 3, kBig)},
      {"initial_orientation.planes.distance_threshold_m",
       Number(&po.distance_threshold_m, 0.0, 100.0)},
      {"initial_orientation.planes.distance_threshold_per_m",
       Number(&po.distance_threshold_per_m, 0.0, 100.0)},
      {"initial_orientation.planes.ransac_iterations", Number(&po.ransac_iterations, 1, kBig)},
      {"initial_orientation.planes.seed", Number<uint64_t>(&po.seed, 0, UINT64_MAX)},
      {"initial_orientation.planes.expected_up_cam0", Vector3(&po.expected_up_cam0)},
      {"initial_orientation.planes.max_normal_deviation_deg",
       Number(&po.max_normal_deviation_deg, 0.0, 180.0)},
      {"initial_orientation.planes.manhattan_refinement", Bool(&po.manhattan_refinement)},
      {"initial_orientation.sample_step_px", Number(&io.sample_step_px, 1, 1000)},
      {"initial_orientation.refine_floor", Bool(&io.refine_floor)},
      {"initial_orientation.floor_refinement.max_iterations", Number(&fr.max_iterations, 1, 1000)},
      {"initial_orientation.floor_refinement.converged_px", Number(&fr.converged_px, 1e-9, 100.0)},
      {"initial_orientation.floor_refinement.huber_iterations",
       Number(&fr.huber_iterations, 0, 999)},
      {"initial_orientation.floor_refinement.huber_sigmas", Number(&fr.huber_sigmas, 1e-3, 100.0)},
      {"initial_orientation.floor_refinement.tukey_sigmas", Number(&fr.tukey_sigmas, 1e-3, 100.0)},
      {"initial_orientation.floor_refinement.region_radius_px",
       Number(&fr.region_radius_px, 1, 50)},
      {"initial_orientation.floor_refinement.region_outlier_ratio",
       Number(&fr.region_outlier_ratio, 1.0, 1000.0)},
      {"initial_orientation.floor_refinement.min_sigma_grey",
       Number(&fr.min_sigma_grey, 1e-6, 255.0)},
      {"initial_orientation.floor_refinement.min_pixels", Number(&fr.min_pixels, 5, kBig)},
      {"initial_orientation.floor_refinement.max_tilt_change_deg",
       Number(&fr.max_tilt_change_deg, 1e-6, 90.0)},
      {"initial_orientation.floor_refinement.max_offset_change",
       Number(&fr.max_offset_change, 1e-6, 100.0)},
      {"initial_orientation.requires_wall", Bool(&io.requires_wall)},
      {"initial_orientation.up_from_mounting", Bool(&io.up_from_mounting)},
      {"tracker.matcher.type",
       Enum(&m.type, {vo::MatcherType::kSvdProximity, vo::MatcherType::kSvdNcc,
                      vo::MatcherType::kSvdNccGabor, vo::MatcherType::kNccMutual,
                      vo::MatcherType::kLucasKanade, vo::MatcherType::kKalman,
                      vo::MatcherType::kSiftRatio})},
      {"tracker.matcher.prediction",
       Enum(&m.prediction, {vo::PredictionMode::kNone, vo::PredictionMode::kMotionPrior})},
      {"tracker.matcher.ncc.window_px", Number(&m.ncc.window_px, 3, 63)},
      {"tracker.matcher.ncc.min_stddev", Number(&m.ncc.min_stddev, 0.0, 255.0)},
      {"tracker.matcher.gabor.num_orientations", Number(&m.gabor.num_orientations, 1, 16)},
      {"tracker.matcher.gabor.wavelengths_px", Wavelengths(&m.gabor.wavelengths_px)},
      {"tracker.matcher.gabor.sigma_per_wavelength",
       Number(&m.gabor.sigma_per_wavelength, 0.01, 10.0)},
      {"tracker.matcher.gabor.aspect", Number(&m.gabor.aspect, 0.01, 100.0)},
      {"tracker.matcher.gabor.truncate_sigmas", Number(&m.gabor.truncate_sigmas, 0.1, 100.0)},
      {"tracker.matcher.gabor.half_res_min_wavelength_px",
       Number(&m.gabor.half_res_min_wavelength_px, 0.0, 1000.0)},
      {"tracker.matcher.gabor.subpixel_phase_correction", Bool(&m.gabor.subpixel_phase_correction)},
      {"tracker.matcher.gabor.weighting",
       Enum(&m.gabor.weighting, {vo::PhaseWeighting::kUniform, vo::PhaseWeighting::kAmplitude})},
      {"tracker.matcher.gabor.min_amplitude", Number(&m.gabor.min_amplitude, 0.0, kInf)},
      {"tracker.matcher.gabor.phase_exponent", Number(&m.gabor.phase_exponent, 0.0, 100.0)},
      {"tracker.matcher.gabor.unknown_phase_diff_rad",
       Number(&m.gabor.unknown_phase_diff_rad, 0.0, 4.0)},
      {"tracker.matcher.svd.sigma_px", Number(&m.svd.sigma_px, 0.1, 1000.0)},
      {"tracker.matcher.svd.cutoff_sigmas", Number(&m.svd.cutoff_sigmas, 0.1, 100.0)},
      {"tracker.matcher.svd.min_entry", Number(&m.svd.min_entry, 0.0, 1.0)},
      {"tracker.matcher.svd.min_weight", Number(&m.svd.min_weight, 0.0, 1.0)},
      {"tracker.matcher.svd.min_pairing", Number(&m.svd.min_pairing, 0.0, 1.0)},
      {"tracker.matcher.svd.min_ncc", Number(&m.svd.min_ncc, -1.0, 1.0)},
      {"tracker.matcher.svd.gabor_min_ncc", Number(&m.svd.gabor_min_ncc, -1.0, 1.0)},
      {"tracker.matcher.svd.max_phase_diff_rad", Number(&m.svd.max_phase_diff_rad, 0.0, 4.0)},
      {"tracker.matcher.svd.dense", Bool(&m.svd.dense)},
      {"tracker.matcher.svd.max_component_size", Number(&m.svd.max_component_size, 1, kBig)},
      {"tracker.matcher.svd.guard_growth", Number(&m.svd.guard_growth, 0.0, kInf)},
      {"tracker.matcher.svd.guard_max_entry", Number(&m.svd.guard_max_entry, 0.0, 1.0)},
      {"tracker.matcher.svd.jacobi_max_size", Number(&m.svd.jacobi_max_size, 0, kBig)},
      {"tracker.matcher.svd.coherence_sigmas", Number(&m.svd.coherence_sigmas, 0.0, 100.0)},
      {"tracker.matcher.svd.coherence_min_px", Number(&m.svd.coherence_min_px, 0.0, 1000.0)},
      {"tracker.matcher.svd.coherence_radius_px", Number(&m.svd.coherence_radius_px, 0.0, 10000.0)},
      {"tracker.matcher.svd.coherence_neighbours", Number(&m.svd.coherence_neighbours, 0, kBig)},
      {"tracker.matcher.ncc_mutual.search_radius_px",
       Number(&m.ncc_mutual.search_radius_px, 0.1, 10000.0)},
      {"tracker.matcher.ncc_mutual.min_score", Number(&m.ncc_mutual.min_score, 0.0, 1.0)},
      {"tracker.matcher.lucas_kanade.window_px", Number(&m.lucas_kanade.window_px, 5, 101)},
      {"tracker.matcher.lucas_kanade.max_level", Number(&m.lucas_kanade.max_level, 0, 8)},
      {"tracker.matcher.lucas_kanade.max_iterations",
       Number(&m.lucas_kanade.max_iterations, 1, 10000)},
      {"tracker.matcher.lucas_kanade.epsilon_px", Number(&m.lucas_kanade.epsilon_px, 0.0, 100.0)},
      {"tracker.matcher.lucas_kanade.min_eig_threshold",
       Number(&m.lucas_kanade.min_eig_threshold, 0.0, 1.0)},
      {"tracker.matcher.lucas_kanade.max_fb_error_px",
       Number(&m.lucas_kanade.max_fb_error_px, -1.0, 1000.0)},
      {"tracker.matcher.lucas_kanade.association_radius_px",
       Number(&m.lucas_kanade.association_radius_px, 0.0, 1000.0)},
      {"tracker.matcher.kalman.measurement_noise_px",
       Number(&m.kalman.measurement_noise_px, 0.0, 1000.0)},
      {"tracker.matcher.kalman.process_noise_px", Number(&m.kalman.process_noise_px, 0.0, 1000.0)},
      {"tracker.matcher.kalman.initial_velocity_std_px",
       Number(&m.kalman.initial_velocity_std_px, 0.0, 10000.0)},
      {"tracker.matcher.kalman.gate_chi2", Number(&m.kalman.gate_chi2, 0.0, kInf)},
      {"tracker.matcher.kalman.max_search_radius_px",
       Number(&m.kalman.max_search_radius_px, 0.0, 10000.0)},
      {"tracker.matcher.kalman.gradient_window_px", Number(&m.kalman.gradient_window_px, 1, 101)},
      {"tracker.matcher.kalman.gradient_noise", Number(&m.kalman.gradient_noise, 0.0, kInf)},
      {"tracker.matcher.kalman.gradient_process_noise",
       Number(&m.kalman.gradient_process_noise, 0.0, kInf)},
      {"tracker.matcher.kalman.min_ncc", Number(&m.kalman.min_ncc, -1.0, 1.0)},
      {"tracker.matcher.kalman.ncc_scale", Number(&m.kalman.ncc_scale, 0.0, kInf)},
      {"tracker.matcher.kalman.max_cost", Number(&m.kalman.max_cost, 0.0, kInf)},
      {"tracker.matcher.sift_ratio.ratio", Number(&m.sift_ratio.ratio, 0.01, 1.0)},
      {"tracker.matcher.sift_ratio.mutual", Bool(&m.sift_ratio.mutual)},
      {"tracker.matcher.sift_ratio.search_radius_px",
       Number(&m.sift_ratio.search_radius_px, -1.0, kInf)},
      {"tracker.coarse_to_fine", Bool(&t.coarse_to_fine)},
      {"tracker.image_shift.coarsest_max_width_px",
       Number(&t.image_shift.coarsest_max_width_px, 8, 100000)},
      {"tracker.image_shift.max_shift_fraction_x",
       Number(&t.image_shift.max_shift_fraction_x, 0.01, 0.9)},
      {"tracker.image_shift.max_shift_fraction_y",
       Number(&t.image_shift.max_shift_fraction_y, 0.01, 0.9)},
      {"tracker.image_shift.refine_radius_px", Number(&t.image_shift.refine_radius_px, 1, 100)},
      {"tracker.image_shift.finest_level", Number(&t.image_shift.finest_level, 0, 10)},
      {"tracker.image_shift.min_overlap_fraction",
       Number(&t.image_shift.min_overlap_fraction, 0.01, 1.0)},
      {"tracker.image_shift.min_score", Number(&t.image_shift.min_score, -1.0, 1.0)},
      {"tracker.image_shift.subpixel", Bool(&t.image_shift.subpixel)},
      {"tracker.last_motion_pass", Bool(&t.last_motion_pass)},
      {"tracker.prior_radius_scale", Number(&t.prior_radius_scale, 0.05, 20.0)},
      {"tracker.shift_radius_scale", Number(&t.shift_radius_scale, 0.05, 20.0)},
      {"tracker.confident_min_inliers", Number(&t.confident_min_inliers, 0, 100000)},
      {"tracker.confident_inlier_fraction", Number(&t.confident_inlier_fraction, 0.0, 1.0)},
      {"tracker.guided_rematch", Bool(&t.guided_rematch)},
      {"tracker.guided_radius_scale", Number(&t.guided_radius_scale, 0.05, 20.0)},
      {"motion.ransac.inlier_threshold_px", Number(&r.inlier_threshold_px, 0.01, 1000.0)},
      {"motion.ransac.confidence", Number(&r.confidence, 0.5, 0.999999)},
      {"motion.ransac.min_iterations", Number(&r.min_iterations, 0, kBig)},
      {"motion.ransac.max_iterations", Number(&r.max_iterations, 1, kBig)},
      {"motion.ransac.min_inliers", Number(&r.min_inliers, 3, kBig)},
      {"motion.ransac.num_seeded_iterations", Number(&r.num_seeded_iterations, 0, kBig)},
      {"motion.ransac.stable_pool_fraction", Number(&r.stable_pool_fraction, 0.0, 1.0)},
      {"motion.ransac.min_stable_pool_size", Number(&r.min_stable_pool_size, 0, kBig)},
      {"motion.ransac.seed", Number<uint64_t>(&r.seed, 0, UINT64_MAX)},
      {"motion.ransac.sample_collinear_tolerance", Number(&r.sample_collinear_tolerance, 0.0, 1.0)},
      {"motion.ransac.refit_iterations", Number(&r.refit_iterations, 0, 1000)},
      {"motion.ransac.refit_depth_weighted", Bool(&r.refit_depth_weighted)},
      {"motion.ransac.local_optimization_iterations",
       Number(&r.local_optimization_iterations, 0, 1000)},
      {"motion.ransac.refine_nonlinear", Bool(&r.refine_nonlinear)},
      {"motion.ransac.refine_max_iterations", Number(&r.refine_max_iterations, 0, 10000)},
      {"motion.ransac.refine_points", Bool(&r.refine_points)},
      {"motion.min_inliers", Number(&mo.min_inliers, 3, 100000)},
      {"motion.ransac_refine_with_ba", Bool(&mo.ransac_refine_with_ba)},
      {"motion.reliable_min_inliers", Number(&mo.reliable_min_inliers, 3, 100000)},
      {"motion.prior_update_exponent", Number(&mo.prior_update_exponent, 1.0, 100.0)},
      {"motion.vehicle_max_weak_tilt_deg", Number(&mo.vehicle_max_weak_tilt_deg, 1e-6, 180.0)},
      {"motion.vehicle_max_weak_lift_m", Number(&mo.vehicle_max_weak_lift_m, 1e-6, 100.0)},
      {"motion.few_point.enabled", Bool(&mo.few_point_motion)},
      {"motion.few_point.min_features", Number(&mo.few_point_min_features, 1, 100000)},
      {"motion.few_point.min_inliers", Number(&mo.few_point.min_inliers, 1, 100000)},
      {"motion.few_point.min_inlier_fraction", Number(&mo.few_point.min_inlier_fraction, 0.0, 1.0)},
      {"motion.few_point.inlier_threshold_px",
       Number(&mo.few_point.inlier_threshold_px, 1e-6, 1000.0)},
      {"motion.few_point.measurement_sigma_px",
       Number(&mo.few_point.measurement_sigma_px, 1e-6, 1000.0)},
      {"motion.few_point.prior_rotation_sigma_deg",
       Number(&mo.few_point.prior_rotation_sigma_deg, 1e-6, 180.0)},
      {"motion.few_point.prior_translation_sigma_m",
       Number(&mo.few_point.prior_translation_sigma_m, 1e-9, 100.0)},
      {"motion.few_point.max_iterations", Number(&mo.few_point.max_iterations, 1, 1000)},
      {"motion.few_point.max_shift_disagreement_px",
       Number(&mo.few_point_max_shift_disagreement_px, 0.0, 100000.0)},
      {"motion.few_point.prior_update", Number(&mo.few_point_prior_update, 0.0, 1.0)},
      {"recovery.rotation_from_shift", Bool(&rc.rotation_from_shift)},
      {"recovery.rotation_min_shift_score", Number(&rc.rotation_min_shift_score, -1.0, 1.0)},
      {"recovery.rotation_min_peak_ratio", Number(&rc.rotation_min_peak_ratio, 1.0, 1000.0)},
      {"recovery.rotation_min_residual_px", Number(&rc.rotation_min_residual_px, 0.0, 1000.0)},
      {"recovery.vehicle_rotation_min_shift_score",
       Number(&rc.vehicle_rotation_min_shift_score, -1.0, 1.0)},
      {"recovery.vehicle_rotation_min_peak_ratio",
       Number(&rc.vehicle_rotation_min_peak_ratio, 1.0, 1000.0)},
      {"recovery.vehicle_max_vertical_shift_ratio",
       Number(&rc.vehicle_max_vertical_shift_ratio, 0.0, 1000.0)},
      {"recovery.chain_lost_frames", Bool(&rc.chain_lost_frames)},
      {"recovery.vehicle_bridge.enabled", Bool(&rc.vehicle_bridge_alignment)},
      {"recovery.vehicle_bridge.gate_px", Number(&rc.vehicle_bridge.gate_px, 1e-6, 1000.0)},
      {"recovery.vehicle_bridge.min_pairs", Number(&rc.vehicle_bridge.min_pairs, 1, 100000)},
      {"recovery.vehicle_bridge.disparity_sigma_px",
       Number(&rc.vehicle_bridge.disparity_sigma_px, 1e-6, 1000.0)},
      {"recovery.vehicle_bridge.step_sigma_m",
       Number(&rc.vehicle_bridge.step_sigma_m, 1e-9, 100.0)},
  };
  for (auto& key : DirectAlignmentKeys("recovery.vehicle_direct", &rc.vehicle_direct_alignment,
                                       &rc.vehicle_direct)) {
    keys.push_back(std::move(key));
  }
  for (auto& key :
       DirectAlignmentKeys("recovery.free_direct", &rc.free_direct_alignment, &rc.free_direct)) {
    keys.push_back(std::move(key));
  }
  std::vector<std::pair<std::string, Entry>> rest = {
      {"recovery.reinit_after_lost_frames", Number(&rc.reinit_after_lost_frames, 1, 100000)},
      {"back_end.bundle_adjustment", Bool(&o->back_end.bundle_adjustment)},
      {"back_end.window_frames", Number(&o->back_end.window_frames, 3, 10)},
      {"back_end.max_points", Number(&o->back_end.max_points, 0, 100000)},
      {"back_end.max_correction_m", Number(&o->back_end.max_correction_m, 1e-9, kInf)},
      {"back_end.max_correction_deg", Number(&o->back_end.max_correction_deg, 1e-9, 360.0)},
      {"back_end.prior_weight", Number(&o->back_end.prior_weight, 0.0, 1.0)},
      {"back_end.ba.max_num_iterations", Number(&ba.max_num_iterations, 1, 1000)},
      {"back_end.ba.function_tolerance", Number(&ba.function_tolerance, 0.0, 1.0)},
      {"back_end.ba.gradient_tolerance", Number(&ba.gradient_tolerance, 0.0, 1.0)},
      {"back_end.ba.parameter_tolerance", Number(&ba.parameter_tolerance, 0.0, 1.0)},
      {"back_end.ba.loss",
       Enum(&ba.loss, {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy})},
      {"back_end.ba.loss_scale_px", Number(&ba.loss_scale_px, 0.01, 100.0)},
      {"back_end.ba.outlier_threshold_px", Number(&ba.outlier_threshold_px, 1e-6, 1e6)},
      {"back_end.ba.num_fixed_poses", Number(&ba.num_fixed_poses, 1, 10)},
      {"back_end.ba.min_frames_per_point", Number(&ba.min_frames_per_point, 1, 10)},
      {"back_end.ba.solver", Enum(&ba.solver, {BaSolver::kCeres, BaSolver::kSchurLm})},
      {"back_end.ba.linear_solver",
       Enum(&ba.linear_solver,
            {BaLinearSolver::kAuto, BaLinearSolver::kSparseSchur, BaLinearSolver::kDenseSchur})},
      {"back_end.ba.analytic_jacobians", Bool(&ba.analytic_jacobians)},
      {"back_end.vehicle_planar.enabled", Bool(&o->back_end.vehicle_planar.enabled)},
      {"back_end.vehicle_planar.tilt_sigma_deg",
       Number(&o->back_end.vehicle_planar.tilt_sigma_deg, 1e-9, 180.0)},
      {"back_end.vehicle_planar.lift_sigma_m",
       Number(&o->back_end.vehicle_planar.lift_sigma_m, 1e-9, 100.0)},
      {"back_end.vehicle_planar.slip_sigma_m",
       Number(&o->back_end.vehicle_planar.slip_sigma_m, 1e-9, 100.0)},
      {"back_end.flat_floor.enabled", Bool(&o->back_end.flat_floor.enabled)},
      {"back_end.flat_floor.tilt_sigma_deg",
       Number(&o->back_end.flat_floor.tilt_sigma_deg, 1e-9, 180.0)},
      {"back_end.flat_floor.height_sigma_m",
       Number(&o->back_end.flat_floor.height_sigma_m, 1e-9, 100.0)},
      {"imu.gyro_prior", Bool(&o->imu.gyro_prior)},
      {"imu.few_point_motion", Bool(&o->imu.few_point_motion)},
      {"imu.few_point_after_loss", Bool(&o->imu.few_point_after_loss)},
      {"imu.ba_rotation_prior", Bool(&o->imu.ba_rotation_prior)},
      {"imu.max_weak_rotation_error_deg", Number(&o->imu.max_weak_rotation_error_deg, 1e-9, 180.0)},
      {"imu.min_rotation_sigma_deg", Number(&o->imu.min_rotation_sigma_deg, 1e-9, 180.0)},
      {"imu.initial_bias_sigma_radps", Number(&o->imu.initial_bias_sigma_radps, 0.0, 100.0)},
      {"imu.bias_gain", Number(&o->imu.bias_gain, 0.0, 1.0)},
      {"imu.bias_window_s", Number(&o->imu.bias_window_s, 1e-9, 1e6)},
      {"imu.max_bias_radps", Number(&o->imu.max_bias_radps, 1e-9, 100.0)},
      {"imu.standing_start_s", Number(&o->imu.standing_start_s, 0.0, 1e6)},
      {"imu.standing_max_std_radps", Number(&o->imu.standing_max_std_radps, 1e-9, 100.0)},
      {"imu.max_standing_bias_radps", Number(&o->imu.max_standing_bias_radps, 1e-9, 100.0)},
  };
  for (auto& key : rest) keys.push_back(std::move(key));
  return keys;
}

// The keys of vo_options.yaml before the options were grouped by the pipeline's stages (issue
// #32), each with its new key, or the constant it became (a numerical guard no user tunes).
// An entry also renames every key below it ("matcher" -> "tracker.matcher": matcher.type is
// tracker.matcher.type); the longest entry that matches wins. Old keys are refused, never read:
// the message names the new key.
struct RenamedKey {
  const char* old_key;
  const char* new_key;   // "" when the option became a constant
  const char* constant;  // that constant (new_key "")
};
const std::vector<RenamedKey>& RenamedKeys() {
  static const std::vector<RenamedKey> table = {
      {"adaptive_min_features", "front_end.adaptive_min_features", nullptr},
      {"adaptive_quality_level", "front_end.adaptive_quality_level", nullptr},
      {"ba", "back_end.ba", nullptr},
      {"ba.min_depth_m", "", "vo::BundleAdjustmentOptions::kMinDepthM"},
      {"ba_max_correction_deg", "back_end.max_correction_deg", nullptr},
      {"ba_max_correction_m", "back_end.max_correction_m", nullptr},
      {"ba_max_points", "back_end.max_points", nullptr},
      {"ba_window_frames", "back_end.window_frames", nullptr},
      {"depth", "front_end.depth", nullptr},
      {"derive_num_disparities", "front_end.derive_num_disparities", nullptr},
      {"detector", "front_end.detector", nullptr},
      {"disparity", "front_end.disparity", nullptr},
      {"disparity_min_depth_m", "front_end.disparity_min_depth_m", nullptr},
      {"disparity_mode", "front_end.disparity_mode", nullptr},
      {"disparity_range_from_scene", "front_end.disparity_range_from_scene", nullptr},
      {"disparity_range_margin", "front_end.disparity_range_margin", nullptr},
      {"disparity_range_margin_px", "front_end.disparity_range_margin_px", nullptr},
      {"estimate_initial_orientation", "initial_orientation.enabled", nullptr},
      {"floor_refinement", "initial_orientation.floor_refinement", nullptr},
      {"matcher", "tracker.matcher", nullptr},
      {"max_num_disparities", "front_end.max_num_disparities", nullptr},
      {"min_features", "front_end.min_features", nullptr},
      {"min_inliers", "motion.min_inliers", nullptr},
      {"orientation", "initial_orientation.planes", nullptr},
      {"orientation_floor_refinement", "initial_orientation.refine_floor", nullptr},
      {"orientation_requires_wall", "initial_orientation.requires_wall", nullptr},
      {"orientation_sample_step_px", "initial_orientation.sample_step_px", nullptr},
      {"orientation_up_from_mounting", "initial_orientation.up_from_mounting", nullptr},
      {"prior_weight", "back_end.prior_weight", nullptr},
      {"ransac", "motion.ransac", nullptr},
      {"ransac.min_depth_m", "", "vo::RansacOptions::kMinDepthM"},
      {"ransac_refine_with_ba", "motion.ransac_refine_with_ba", nullptr},
      {"reinit_after_lost_frames", "recovery.reinit_after_lost_frames", nullptr},
      {"tracking.chain_lost_frames", "recovery.chain_lost_frames", nullptr},
      {"tracking.coarse_to_fine", "tracker.coarse_to_fine", nullptr},
      {"tracking.confident_inlier_fraction", "tracker.confident_inlier_fraction", nullptr},
      {"tracking.confident_min_inliers", "tracker.confident_min_inliers", nullptr},
      {"tracking.few_point", "motion.few_point", nullptr},
      {"tracking.few_point.axle_behind_camera_m", "vehicle.axle_behind_camera_m", nullptr},
      {"tracking.few_point.min_depth_m", "", "vo::PriorMotionOptions::kMinDepthM"},
      {"tracking.few_point.no_sideways_slip", "vehicle.no_sideways_slip", nullptr},
      {"tracking.few_point_max_shift_disagreement_px", "motion.few_point.max_shift_disagreement_px",
       nullptr},
      {"tracking.few_point_min_features", "motion.few_point.min_features", nullptr},
      {"tracking.few_point_motion", "motion.few_point.enabled", nullptr},
      {"tracking.few_point_prior_update", "motion.few_point.prior_update", nullptr},
      {"tracking.ground_vehicle", "vehicle.enabled", nullptr},
      {"tracking.guided_radius_scale", "tracker.guided_radius_scale", nullptr},
      {"tracking.guided_rematch", "tracker.guided_rematch", nullptr},
      {"tracking.image_shift", "tracker.image_shift", nullptr},
      {"tracking.last_motion_pass", "tracker.last_motion_pass", nullptr},
      {"tracking.prior_radius_scale", "tracker.prior_radius_scale", nullptr},
      {"tracking.prior_update_exponent", "motion.prior_update_exponent", nullptr},
      {"tracking.reliable_min_inliers", "motion.reliable_min_inliers", nullptr},
      {"tracking.rotation_from_shift", "recovery.rotation_from_shift", nullptr},
      {"tracking.rotation_min_peak_ratio", "recovery.rotation_min_peak_ratio", nullptr},
      {"tracking.rotation_min_residual_px", "recovery.rotation_min_residual_px", nullptr},
      {"tracking.rotation_min_shift_score", "recovery.rotation_min_shift_score", nullptr},
      {"tracking.shift_radius_scale", "tracker.shift_radius_scale", nullptr},
      {"tracking.vehicle_ba_lift_sigma_m", "back_end.vehicle_planar.lift_sigma_m", nullptr},
      {"tracking.vehicle_ba_slip_sigma_m", "back_end.vehicle_planar.slip_sigma_m", nullptr},
      {"tracking.vehicle_ba_tilt_sigma_deg", "back_end.vehicle_planar.tilt_sigma_deg", nullptr},
      {"tracking.vehicle_bridge", "recovery.vehicle_bridge", nullptr},
      {"tracking.vehicle_bridge_alignment", "recovery.vehicle_bridge.enabled", nullptr},
      {"tracking.vehicle_direct", "recovery.vehicle_direct", nullptr},
      {"tracking.vehicle_direct_alignment", "recovery.vehicle_direct.enabled", nullptr},
      {"tracking.vehicle_flat_floor", "back_end.flat_floor.enabled", nullptr},
      {"tracking.vehicle_floor_height_sigma_m", "back_end.flat_floor.height_sigma_m", nullptr},
      {"tracking.vehicle_floor_tilt_sigma_deg", "back_end.flat_floor.tilt_sigma_deg", nullptr},
      {"tracking.vehicle_max_vertical_shift_ratio", "recovery.vehicle_max_vertical_shift_ratio",
       nullptr},
      {"tracking.vehicle_max_weak_lift_m", "motion.vehicle_max_weak_lift_m", nullptr},
      {"tracking.vehicle_max_weak_tilt_deg", "motion.vehicle_max_weak_tilt_deg", nullptr},
      {"tracking.vehicle_planar_ba", "back_end.vehicle_planar.enabled", nullptr},
      {"tracking.vehicle_rotation_min_peak_ratio", "recovery.vehicle_rotation_min_peak_ratio",
       nullptr},
      {"tracking.vehicle_rotation_min_shift_score", "recovery.vehicle_rotation_min_shift_score",
       nullptr},
      {"use_bundle_adjustment", "back_end.bundle_adjustment", nullptr},
  };
  return table;
}

}  // namespace

std::string RenamedVoKey(const std::string& old_key, std::string* constant) {
  const RenamedKey* best = nullptr;
  for (const RenamedKey& k : RenamedKeys()) {
    const std::string o = k.old_key;
    const bool match = old_key == o || old_key.rfind(o + ".", 0) == 0;
    if (match && (best == nullptr || o.size() > std::string(best->old_key).size())) best = &k;
  }
  if (best == nullptr) return "";
  if (best->constant != nullptr) {
    if (constant != nullptr) *constant = best->constant;
    return "";
  }
  return best->new_key + old_key.substr(std::string(best->old_key).size());
}

namespace {

// The refusal of an old key (RenamedKeys): false with the message when `key` is one, true when
// it is not.
bool RefuseOldKey(YamlReader& r, const YAML::Node& at, const std::string& key) {
  std::string constant;
  const std::string renamed = RenamedVoKey(key, &constant);
  if (!renamed.empty())
    return r.Fail(at, key,
                  "renamed: the options are grouped by the pipeline's stages; write `" + renamed +
                      "` (docs/DESIGN.md, \"VO options by stage\")");
  if (!constant.empty())
    return r.Fail(at, key,
                  "no longer an option: a numerical guard, now the constant " + constant +
                      "; remove the key");
  return true;
}

// Walks the mapping; leaves (scalars and the list-valued options) are read by dotted key.
// `seen` holds the line of every key applied so far: the same option given twice, once dotted
// and once nested ("matcher.type: a" and "matcher: {type: b}"), is a duplicate too.
bool Apply(YamlReader& r, const YAML::Node& node, const std::string& prefix,
           std::map<std::string, Entry>& entries, std::map<std::string, int>* seen) {
  for (const auto& kv : node) {
    const std::string key = YamlReader::Join(prefix, kv.first.Scalar());
    const YAML::Node& v = kv.second;
    const int line = kv.first.Mark().line + 1;
    auto it = entries.find(key);
    if (it != entries.end()) {
      const auto [first, inserted] = seen->emplace(key, line);
      if (!inserted)
        return r.Fail(kv.first, key,
                      "duplicate (first at line " + std::to_string(first->second) + ")");
    }
    if (it == entries.end()) {
      if (!RefuseOldKey(r, kv.first, key)) return false;
      if (v.IsMap()) {
        bool any = false;
        for (const auto& e : entries) any |= e.first.rfind(key + ".", 0) == 0;
        for (const RenamedKey& k : RenamedKeys())
          any |= std::string(k.old_key).rfind(key + ".", 0) == 0;
        if (any) {
          if (!Apply(r, v, key, entries, seen)) return false;
          continue;
        }
      }
      return r.Fail(kv.first, key,
                    "unknown key (see `vobench run --help` and results' vo_options.yaml for the "
                    "supported keys)");
    }
    if (it->second.sequence && !v.IsSequence()) return r.Fail(kv.first, key, "expected a list");
    if (!it->second.sequence && !v.IsScalar())
      return r.Fail(kv.first, key, "expected a single value");
    if (!it->second.read(r, v, key)) return false;
  }
  return true;
}

}  // namespace

bool ParseVoConfig(const std::string& yaml_text, const std::string& source_name,
                   vo::OdometryOptions* options, std::string* error) {
  YamlReader r(source_name);
  if (!r.Parse(yaml_text)) return r.Report(error);
  YAML::Node root = r.root();      // not const: a missing key reads as undefined, not invalid
  if (root.IsNull()) return true;  // an empty file: defaults
  if (!root.IsMap()) {
    *error = source_name + ": expected a YAML mapping of VO options";
    return false;
  }
  vo::OdometryOptions o = *options;
  std::map<std::string, Entry> entries;
  for (auto& e : Registry(&o)) entries.emplace(e.first, e.second);
  std::map<std::string, int> seen;
  if (!Apply(r, root, "", entries, &seen)) return r.Report(error);
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
    while (common < open.size() && common + 1 < parts.size() && open[common] == parts[common])
      ++common;
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
