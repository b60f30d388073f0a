// Bindings of farlio::eval: options and results are plain fields; per-pose arrays are numpy copies.
#include <nanobind/eigen/dense.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "farlio/eval/metrics.hpp"
#include "repr.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

using namespace farlio::eval;

/// A numpy array owning a copy of `values`.
template <typename T>
nb::ndarray<nb::numpy, T> to_numpy(const std::vector<T>& values) {
  return owned_array(values, {values.size()});
}

/// (N, 3) array of the positions of `poses` (a copy).
nb::ndarray<nb::numpy, double> positions(const std::vector<SE3>& poses) {
  std::vector<double> v;
  v.reserve(3 * poses.size());
  for (const auto& p : poses) v.insert(v.end(), p.translation().data(), p.translation().data() + 3);
  return owned_array(std::move(v), {poses.size(), 3});
}

/// The headline figures; the parts print themselves in full (result.ape, result.kitti_rpe, ...).
std::string evaluation_repr(const EvaluationResult& r) {
  return Repr("EvaluationResult")
      .field("estimate_poses", r.estimate_poses)
      .field("groundtruth_poses", r.groundtruth_poses)
      .field("associated_poses", r.associated_poses)
      .field("coverage", r.coverage)
      .field("groundtruth_path_length_m", r.groundtruth_path_length_m)
      .field("ape_translation_rmse_m", r.ape.translation_m.rmse)
      .field("ape_rotation_rmse_deg", r.ape.rotation_deg.rmse)
      .field("kitti_translation_pct", r.kitti_rpe.translation_pct)
      .field("kitti_rotation_deg_per_100m", r.kitti_rpe.rotation_deg_per_100m)
      .field("rpe_translation_rmse_m", r.rpe.translation_m.rmse)
      .str();
}

void bind_options(nb::module_& m) {
  nb::enum_<AssociationMode>(m, "AssociationMode")
      .value("INTERPOLATE", AssociationMode::kInterpolate)
      .value("NEAREST", AssociationMode::kNearest);
  nb::enum_<AlignmentMethod>(m, "AlignmentMethod")
      .value("UMEYAMA", AlignmentMethod::kUmeyama)
      .value("UMEYAMA_ORIENTATION", AlignmentMethod::kUmeyamaOrientation)
      .value("ORIENTATION", AlignmentMethod::kOrientation)
      .value("ORIGIN", AlignmentMethod::kOrigin);
  nb::enum_<ApeAlignment>(m, "ApeAlignment", "How the APE aligns the estimate onto the ground truth")
      .value("LEAST_SQUARES", ApeAlignment::kLeastSquares, "over every pair (evo_ape --align)")
      .value("ORIGIN", ApeAlignment::kOrigin, "the first pair made one (evo_ape --align_origin)");
  nb::enum_<DeltaUnit>(m, "DeltaUnit").value("FRAMES", DeltaUnit::kFrames).value("METERS", DeltaUnit::kMeters);

  nb::class_<AssociationOptions>(m, "AssociationOptions")
      .def(nb::init<>())
      .def_rw("mode", &AssociationOptions::mode)
      .def_rw("max_time_diff_s", &AssociationOptions::max_time_diff_s)
      .def_rw("max_gt_gap_s", &AssociationOptions::max_gt_gap_s);
  nb::class_<KittiRpeOptions>(m, "KittiRpeOptions")
      .def(nb::init<>())
      .def_rw("step_frames", &KittiRpeOptions::step_frames)
      .def_rw("segment_lengths_m", &KittiRpeOptions::segment_lengths_m, "empty: chosen by path length")
      .def_rw("short_path_threshold_m", &KittiRpeOptions::short_path_threshold_m);
  nb::class_<DeltaRpeOptions>(m, "DeltaRpeOptions")
      .def(nb::init<>())
      .def_rw("delta", &DeltaRpeOptions::delta)
      .def_rw("unit", &DeltaRpeOptions::unit)
      .def_rw("all_pairs", &DeltaRpeOptions::all_pairs)
      .def_rw("rel_delta_tol", &DeltaRpeOptions::rel_delta_tol)
      .def_rw("pairs_from_groundtruth", &DeltaRpeOptions::pairs_from_groundtruth);
  nb::class_<EvalOptions>(m, "EvalOptions")
      .def(nb::init<>())
      .def_rw("association", &EvalOptions::association)
      .def_rw("align_with_scale", &EvalOptions::align_with_scale)
      .def_rw("ape_alignment", &EvalOptions::ape_alignment, "LEAST_SQUARES over every pair, or ORIGIN")
      .def_rw("min_spread_to_residual", &EvalOptions::min_spread_to_residual,
              "below this spread across an axis (in RMS residuals) the rotation about it comes from the orientations")
      .def_rw("kitti", &EvalOptions::kitti)
      .def_rw("rpe", &EvalOptions::rpe)
      .def_rw("scan_stamps_ns", &EvalOptions::scan_stamps_ns, "coverage reference; empty: ground-truth stamps");
}

void bind_results(nb::module_& m) {
  nb::class_<ErrorStats>(m, "ErrorStats")
      .def_ro("count", &ErrorStats::count)
      .def_ro("rmse", &ErrorStats::rmse)
      .def_ro("mean", &ErrorStats::mean)
      .def_ro("median", &ErrorStats::median)
      .def_ro("max", &ErrorStats::max)
      .def("__repr__", attribute_repr({"count", "rmse", "mean", "median", "max"}));
  nb::class_<Alignment>(m, "Alignment")
      .def_ro("transform", &Alignment::transform)
      .def_ro("scale", &Alignment::scale)
      .def_ro("rank_deficient", &Alignment::rank_deficient)
      .def_ro("method", &Alignment::method)
      .def("__repr__", attribute_repr({"method", "transform", "scale", "rank_deficient"}));
  nb::class_<ApeResult>(m, "ApeResult")
      .def_ro("alignment", &ApeResult::alignment)
      .def_ro("translation_m", &ApeResult::translation_m)
      .def_ro("rotation_deg", &ApeResult::rotation_deg)
      .def_ro("translation_raw_m", &ApeResult::translation_raw_m)
      .def_ro("rotation_raw_deg", &ApeResult::rotation_raw_deg)
      .def_prop_ro(
          "translation_errors_m", [](const ApeResult& r) { return to_numpy(r.translation_errors_m); },
          nb::rv_policy::move)
      .def_prop_ro(
          "rotation_errors_deg", [](const ApeResult& r) { return to_numpy(r.rotation_errors_deg); },
          nb::rv_policy::move)
      .def_prop_ro(
          "aligned_positions_m", [](const ApeResult& r) { return positions(r.aligned_estimate); }, nb::rv_policy::move)
      .def("__repr__",
           attribute_repr({"translation_m", "rotation_deg", "translation_raw_m", "rotation_raw_deg", "alignment"}));
  nb::class_<KittiLengthError>(m, "KittiLengthError")
      .def_ro("length_m", &KittiLengthError::length_m)
      .def_ro("segment_count", &KittiLengthError::segment_count)
      .def_ro("translation_pct", &KittiLengthError::translation_pct)
      .def_ro("rotation_deg_per_100m", &KittiLengthError::rotation_deg_per_100m)
      .def("__repr__", attribute_repr({"length_m", "segment_count", "translation_pct", "rotation_deg_per_100m"}));
  nb::class_<KittiRpeResult>(m, "KittiRpeResult")
      .def_ro("segment_lengths_m", &KittiRpeResult::segment_lengths_m)
      .def_ro("segment_count", &KittiRpeResult::segment_count)
      .def_ro("translation_pct", &KittiRpeResult::translation_pct)
      .def_ro("rotation_deg_per_100m", &KittiRpeResult::rotation_deg_per_100m)
      .def_ro("per_length", &KittiRpeResult::per_length)
      .def("__repr__",
           attribute_repr({"segment_count", "translation_pct", "rotation_deg_per_100m", "segment_lengths_m"}));
  nb::class_<DeltaRpeResult>(m, "DeltaRpeResult")
      .def_ro("pairs", &DeltaRpeResult::pairs)
      .def_ro("translation_m", &DeltaRpeResult::translation_m)
      .def_ro("rotation_deg", &DeltaRpeResult::rotation_deg)
      .def_prop_ro(
          "translation_errors_m", [](const DeltaRpeResult& r) { return to_numpy(r.translation_errors_m); },
          nb::rv_policy::move)
      .def("__repr__", attribute_repr({"translation_m", "rotation_deg"}));  // translation_m.count: the pairs
  nb::class_<EvaluationResult>(m, "EvaluationResult")
      .def_ro("estimate_poses", &EvaluationResult::estimate_poses)
      .def_ro("groundtruth_poses", &EvaluationResult::groundtruth_poses)
      .def_ro("associated_poses", &EvaluationResult::associated_poses)
      .def_ro("coverage", &EvaluationResult::coverage)
      .def_ro("groundtruth_path_length_m", &EvaluationResult::groundtruth_path_length_m)
      .def_prop_ro(
          "stamps_ns", [](const EvaluationResult& r) { return to_numpy(r.stamps_ns); }, nb::rv_policy::move)
      .def_prop_ro(
          "groundtruth_positions_m", [](const EvaluationResult& r) { return positions(r.groundtruth); },
          nb::rv_policy::move)
      .def_ro("ape", &EvaluationResult::ape)
      .def_ro("kitti_rpe", &EvaluationResult::kitti_rpe)
      .def_ro("rpe", &EvaluationResult::rpe)
      .def("__repr__", &evaluation_repr);
}

}  // namespace

void bind_eval(nb::module_& m) {
  bind_options(m);
  bind_results(m);
  m.def("evaluate", &evaluate, "estimate"_a, "groundtruth"_a, "options"_a = EvalOptions{},
        "Association, APE (aligned and raw), KITTI-style and evo-style RPE, coverage.");
  m.def("coverage", &coverage, "estimate"_a, "scan_stamps_ns"_a, "max_time_diff_s"_a = kDefaultMaxTimeDiff_s);
}

}  // namespace farlio::python
