#include <algorithm>
#include <string>

#include "farlio/cuda/cuda_executor.cuh"
#include "farlio/cuda/cuda_scan_backend.hpp"
#include "farlio/cuda/device_algorithms.hpp"
#include "farlio/cuda/device_buffer.hpp"
#include "farlio/cuda/device_voxel_map.hpp"
#include "farlio/cuda/map_scratch.hpp"
#include "farlio/cuda/scan_slots.hpp"
#include "farlio/cuda/stage_timer.hpp"
#include "farlio/cuda/warp_search.cuh"
#include "farlio/exec/atomics.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/preprocess/preprocess_point.hpp"
#include "farlio/registration/factor_sums.hpp"

namespace farlio::cuda {
namespace {

constexpr const char* kScanParameter = "cuda.max_scan_points";
constexpr const char* kMapParameter = "cuda.max_map_voxels";
constexpr const char* kFrameMapParameter = "cuda.max_frame_voxels";
/// Bytes of each buffer of the copy ceiling: well beyond the L2 cache of any card.
constexpr std::size_t kCopyBytes = std::size_t{256} << 20;
/// Copies of a frame's inputs in the filled-GPU bandwidth samples.
constexpr std::size_t kFilledCopies = 16;
/// How far the undistortion may move a kept point: 100 m/s over a 0.1 s scan.
constexpr double kUndistortionMargin_m = 10.0;

std::size_t checked_size(std::int64_t value, const char* name) {
  if (value <= 0) throw std::invalid_argument(std::string(name) + " must be > 0");
  return static_cast<std::size_t>(value);
}

/// Items of the shared work arrays: the largest input of any update, plus one.
std::size_t scratch_items(const Config& c) {
  return std::max({checked_size(c.cuda.max_scan_points, kScanParameter),
                   checked_size(c.cuda.max_map_voxels, kMapParameter),
                   checked_size(c.cuda.max_frame_voxels, kFrameMapParameter)}) +
         1;
}

}  // namespace

class CudaScanBackend final : public pipeline::ScanBackend {
 public:
  explicit CudaScanBackend(const Config& config)
      : config_(config),
        max_points_(checked_size(config.cuda.max_scan_points, kScanParameter)),
        algorithms_(scratch_items(config), executor_.stream()),
        scratch_(scratch_items(config), executor_),
        map_(config.map, checked_size(config.cuda.max_map_voxels, kMapParameter), kMapParameter, executor_, algorithms_,
             scratch_),
        frame_map_(pipeline::frame_map_config(config), checked_size(config.cuda.max_frame_voxels, kFrameMapParameter),
                   kFrameMapParameter, executor_, algorithms_, scratch_),
        scans_(max_points_, config.num_threads, executor_.stream()),
        frame_(max_points_, "scan points"),
        world_(max_points_, "scan points"),
        source_points_(max_points_, "source points"),
        source_covs_(max_points_, "source points"),
        matches_(max_points_, "source points"),
        dropped_(1, "non-finite point counts"),
        timer_(executor_.stream()) {
    executor_.synchronize();  // the buffers' initialisation has run
  }

  [[nodiscard]] Device device() const override { return Device::Cuda; }

  void reset(const Config& config) override {
    config_ = config;
    map_.reconfigure(config.map);
    frame_map_.reconfigure(pipeline::frame_map_config(config));
    map_points_ = 0;
  }

  void stage_next(const Scan& next) override { scans_.stage(next); }
  [[nodiscard]] bool last_scan_was_staged() const override { return scans_.last_was_staged(); }

  std::size_t preprocess(const Scan& scan, const deskew::ScanMotion& motion, bool undistort) override {
    timer_.new_frame();
    timer_.start(StageTimer::kPreprocess);
    const std::size_t n = scan.size();
    // the times go up whenever the scan has them: a point with a non-finite time is dropped too
    const bool times = scan.has_time();
    upload_bytes_ = n * (sizeof(Eigen::Vector3f) + (times ? sizeof(float) : 0));
    const ScanSlots::Slot slot = scans_.take(scan);  // staged by stage_next, or uploaded now
    non_finite_points_ = 0;
    frame_size_ = n == 0
                      ? 0
                      : downsample(slot, n, deskew::DeskewTable::sample(motion, static_cast<float>(scan.duration_s())),
                                   undistort, times);
    timer_.stop(StageTimer::kPreprocess);
    return frame_size_;
  }

  [[nodiscard]] std::size_t non_finite_points() const override { return non_finite_points_; }

  /// Non-finite points dropped and counted, the crop and the keys of the downsampling cells (one
  /// thread a point), then the first point of each cell in (cell key, input order), undistorted,
  /// as CpuScanBackend::preprocess on the scan without its non-finite points. The cells' points
  /// are taken before the host reads the cell count: one thread a scan point, those past the
  /// count (on the device) idle.
  std::size_t downsample(const ScanSlots::Slot& slot, std::size_t n, const deskew::DeskewTable& motion, bool undistort,
                         bool times) {
    const preprocess::PreprocessParams pp{preprocess::RangeCrop::from(config_.preprocess), motion, undistort,
                                          1.0f / map_.spacing_m()};
    const Eigen::Vector3f* raw = slot.points;
    const float* time = times ? slot.times : nullptr;
    std::uint64_t* keys = scratch_.keys.data();
    std::int32_t* dropped = dropped_.data();
    FARLIO_CUDA_CHECK(cudaMemsetAsync(dropped, 0, sizeof(std::int32_t), executor_.stream()));
    executor_.for_each(n, [=] __device__(std::size_t i) {
      if (!preprocess::finite_point(raw[i], time ? time + i : nullptr)) {
        keys[i] = map::kEmptyKey;
        exec::atomic_add(dropped, 1);
        return;
      }
      keys[i] = preprocess::downsampling_key(raw[i], pp);
    });
    // the crop keeps points within max_range_m of the sensor: their cells sort on short keys
    const auto window = map::KeyWindow::around(Eigen::Vector3d::Zero(), config_.preprocess.max_range_m,
                                               static_cast<double>(pp.inv_cell_m));
    ReadSlot<std::int32_t> non_finite;
    const std::size_t cells = sort_into_groups(scratch_, executor_, algorithms_, n, window, [&](ReadBack& rb) {
                                take_cell_points(slot, n, pp, undistort);
                                non_finite = rb.post(dropped_.data());
                              }).groups;
    non_finite_points_ = static_cast<std::size_t>(executor_.read_back().value(non_finite));
    return cells;
  }

  /// frame[g] = the first point of cell g, undistorted: one thread a scan point (n), those past
  /// the cell count (on the device) idle.
  void take_cell_points(const ScanSlots::Slot& slot, std::size_t n, const preprocess::PreprocessParams& pp,
                        bool undistort) {
    const Eigen::Vector3f* raw = slot.points;
    const float* times = slot.times;
    const std::int32_t* cells = scratch_.scalars.data() + kScalarGroups;
    const std::int32_t* starts = scratch_.group_start.data();
    const std::int32_t* order = scratch_.sorted_order.data();
    Eigen::Vector3f* frame = frame_.data();
    executor_.for_each(n, [=] __device__(std::size_t g) {
      if (g >= static_cast<std::size_t>(*cells)) return;
      const std::int32_t i = order[starts[g]];
      frame[g] = preprocess::undistorted_point(raw[i], undistort ? times[i] : 0.0f, pp);
    });
  }

  /// The frame map, its points and covariances gathered into the source cloud, and the density:
  /// the host waits for the frame map's groups, then once for the counts of all three.
  pipeline::SourceSummary build_source(double density_range_m, bool covariances) override {
    timer_.start(StageTimer::kSource);
    frame_map_.clear();
    frame_map_.insert_async(frame_.data(), frame_size_, Eigen::Vector3f::Zero(),
                            map::PointLimit::constant(config_.density.frame_map_max_points_per_voxel),
                            points_within_m(),
                            covariances ? map::CovarianceUpdate::Compute : map::CovarianceUpdate::Skip);
    frame_map_.gather_async(source_points_.data(), source_covs_.data(), source_points_.capacity(), kScanParameter);
    frame_map_.mean_points_per_voxel_async(Eigen::Vector3f::Zero(), density_range_m);
    const MapResults r = frame_map_.read_results();
    source_size_ = r.gathered_points;
    timer_.stop(StageTimer::kSource);
    return {source_size_, r.mean_points_per_voxel};
  }

  registration::RegistrationResult register_source(const SE3& initial_guess, const registration::Thresholds& th,
                                                   const RegistrationConfig& config, double time_budget_s) override {
    timer_.start(StageTimer::kRegistration);
    // no point has a correspondence yet (valid = false): each is searched at its first system
    FARLIO_CUDA_CHECK(
        cudaMemsetAsync(matches_.data(), 0, source_size_ * sizeof(registration::Correspondence), executor_.stream()));
    const auto result = registration::gauss_newton(
        [&](const SE3& T, std::size_t stride) { return linear_system(T, th, config, stride); }, initial_guess, config,
        time_budget_s);
    timer_.stop(StageTimer::kRegistration);
    return result;
  }

  /// One Gauss-Newton system over the source points (every stride-th), in two launches. First the
  /// points that moved by registration.correspondence_reuse_m since their last search (all of them
  /// at the first system) are searched again, a warp a point: its lanes look at the 27 voxels around
  /// it together (warp_nearest_neighbor: map::nearest_neighbor's result, in a few dependent reads
  /// where one thread walks the voxels one after the other). Then the shared factor body of each
  /// point at its correspondence, reduced with CUB. The CPU does the same in one pass
  /// (registration::register_scan).
  registration::LinearSystem linear_system(const SE3& T, const registration::Thresholds& th,
                                           const RegistrationConfig& config, std::size_t stride) {
    const registration::FactorParams fp = registration::factor_params(T, th, config);
    const auto reuse2 = static_cast<float>(config.correspondence_reuse_m * config.correspondence_reuse_m);
    const map::ConstMapView target = map_.view();
    const Eigen::Vector4f* points = source_points_.data();
    const map::Cov3* covs = source_covs_.data();
    registration::Correspondence* matches = matches_.data();
    const std::size_t count = registration::strided_count(source_size_, stride);
    // a warp a point: the lanes of t / kWarpLanes are one warp's (the grid's stride is whole warps)
    executor_.for_each(count * kWarpLanes, [=] __device__(std::size_t t) {
      const std::size_t i = t / kWarpLanes * stride;
      const auto lane = static_cast<unsigned>(t % kWarpLanes);
      const Eigen::Vector3f p = fp.R * points[i].head<3>() + fp.t;
      registration::Correspondence c = matches[i];
      if (!registration::search_again(c, p, reuse2)) return;  // the same decision in every lane
      c.nn = warp_nearest_neighbor(target, p, fp.max_correspondence_distance2, lane);
      c.searched_at = p;
      c.valid = true;
      if (lane == 0) matches[i] = c;
    });
    const registration::FactorSums sums = executor_.reduce(
        count, registration::FactorSums::zero(),
        [=] __device__(std::size_t j) {
          const std::size_t i = j * stride;
          const Eigen::Vector4f s = points[i];
          const Eigen::Vector3f p = fp.R * s.head<3>() + fp.t;
          registration::FactorTerms f;
          const bool found = registration::gicp_factor_at(target, s, covs[i], p, matches[i].nn, fp, f);
          return registration::factor_sums_of(found, f);
        },
        registration::AddFactorSums{});
    return registration::to_linear_system(sums);
  }

  /// The frame into the submap at `pose`, the far voxels out: the host waits for the groups of
  /// the insertion, then once for the counts of the insertion, the removal and the points stored.
  map::InsertStats update_map(const SE3& pose, const map::PointLimit& limit, std::size_t* removed_voxels) override {
    timer_.start(StageTimer::kMapUpdate);
    const Eigen::Matrix3f R = pose.rotation().cast<float>();
    const Eigen::Vector3f t = pose.translation().cast<float>();
    const Eigen::Vector3f* frame = frame_.data();
    Eigen::Vector3f* world = world_.data();
    executor_.for_each(frame_size_, [=] __device__(std::size_t i) { world[i] = R * frame[i] + t; });
    map_.insert_async(world_.data(), frame_size_, t, limit, points_within_m());
    map_.remove_far_async(t);
    map_.num_points_async();
    const MapResults r = map_.read_results();
    *removed_voxels = r.removed_voxels;
    map_points_ = r.points;
    last_pose_ = pose;
    timer_.stop(StageTimer::kMapUpdate);
    return r.insert;
  }

  /// In pieces of the scan buffers' size, in input order (as the CPU backend's one insert).
  void load_map(const std::vector<Eigen::Vector3f>& world_points) override {
    const map::PointLimit limit = map::PointLimit::constant(config_.map.max_points_per_voxel);
    for (std::size_t first = 0; first < world_points.size(); first += max_points_) {
      const std::size_t n = std::min(max_points_, world_points.size() - first);
      world_.upload(world_points.data() + first, n, executor_.stream(), kScanParameter);
      map_.insert(world_.data(), n, Eigen::Vector3f::Zero(), limit);
    }
    map_points_ = map_.num_points();
  }
  [[nodiscard]] std::size_t map_voxels() const override { return map_.num_voxels(); }
  [[nodiscard]] std::size_t map_points() const override { return map_points_; }
  [[nodiscard]] map::MapSnapshot map_snapshot() const override { return map_.snapshot(); }
  [[nodiscard]] std::vector<Eigen::Vector3f> frame_points() const override {
    std::vector<Eigen::Vector3f> out(frame_size_);
    frame_.download(out.data(), frame_size_, executor_.stream());
    return out;
  }

  [[nodiscard]] std::size_t memory_bytes() const override {
    return executor_.memory_bytes() + algorithms_.memory_bytes() + scratch_.memory_bytes() + map_.memory_bytes() +
           frame_map_.memory_bytes() + scans_.device_bytes() + frame_.bytes() + world_.bytes() +
           source_points_.bytes() + source_covs_.bytes() + matches_.bytes() + dropped_.bytes();
  }

  bool device_stage_times(pipeline::FrameTimings& t) override {
    timer_.read(t);
    return true;
  }

  /// How far from the sensor a kept point may lie: the crop range, and the sensor's motion during
  /// the scan that the undistortion adds (a farther point only costs a second sort).
  [[nodiscard]] double points_within_m() const { return config_.preprocess.max_range_m + kUndistortionMargin_m; }

  std::vector<BandwidthSample> measure_bandwidth(int repeats) {
    std::vector<BandwidthSample> out{measure_copy(executor_, kCopyBytes, repeats)};
    if (upload_bytes_ > 0) out.push_back(measure_upload(executor_, scans_.frame_staging(), upload_bytes_, repeats));
    const std::size_t n = map_.num_points();
    DeviceBuffer<Eigen::Vector4f> points(n, "map points");
    DeviceBuffer<map::Cov3> covs(n, "map points");
    const std::size_t gathered = map_.gather(points.data(), covs.data(), n, kMapParameter);
    out.push_back(measure_knn(executor_, map_.view(), points.data(), gathered, config_.map.covariance_neighbors,
                              map::kUnboundedDistance2, repeats));
    const auto th = registration::Thresholds::from_sigma(config_.threshold.initial_threshold_m);
    const auto max_d2 = static_cast<float>(th.max_correspondence_m * th.max_correspondence_m);
    out.push_back(measure_gicp_reduction(executor_, map_.view(), source_points_.data(), source_covs_.data(),
                                         source_size_, max_d2, last_pose_, repeats));
    // the same kernels on kFilledCopies copies of their inputs: a launch that fills the GPU (one
    // frame's 5-20k threads do not), to tell latency from bandwidth
    const std::size_t copies = kFilledCopies;
    const auto many_points = replicated(points.data(), gathered, copies);
    out.push_back(measure_knn(executor_, map_.view(), many_points.data(), gathered * copies,
                              config_.map.covariance_neighbors, map::kUnboundedDistance2, repeats));
    const auto many_source = replicated(source_points_.data(), source_size_, copies);
    const auto many_covs = replicated(source_covs_.data(), source_size_, copies);
    out.push_back(measure_gicp_reduction(executor_, map_.view(), many_source.data(), many_covs.data(),
                                         source_size_ * copies, max_d2, last_pose_, repeats));
    for (std::size_t i = out.size() - 2; i < out.size(); ++i) out[i].kernel += " x" + std::to_string(copies);
    return out;
  }

  /// `copies` copies of n device elements, one after the other.
  template <typename T>
  DeviceBuffer<T> replicated(const T* data, std::size_t n, std::size_t copies) {
    DeviceBuffer<T> out(std::max<std::size_t>(n * copies, 1), "bandwidth inputs");
    for (std::size_t c = 0; c < copies && n > 0; ++c) {
      FARLIO_CUDA_CHECK(
          cudaMemcpyAsync(out.data() + c * n, data, n * sizeof(T), cudaMemcpyDeviceToDevice, executor_.stream()));
    }
    return out;
  }

 private:
  Config config_;
  std::size_t max_points_;
  CudaExecutor executor_;
  DeviceAlgorithms algorithms_;
  MapScratch scratch_;
  DeviceVoxelMap map_;
  DeviceVoxelMap frame_map_;
  ScanSlots scans_;                      // the scan's points and times: the frame's, and the next one's (stage_next)
  DeviceBuffer<Eigen::Vector3f> frame_;  // the kept points (sensor frame, scan end)
  DeviceBuffer<Eigen::Vector3f> world_;
  DeviceBuffer<Eigen::Vector4f> source_points_;
  DeviceBuffer<map::Cov3> source_covs_;
  DeviceBuffer<registration::Correspondence> matches_;  // each source point's last search
  DeviceBuffer<std::int32_t> dropped_;                  // non-finite points of the last scan
  std::size_t frame_size_ = 0;
  std::size_t source_size_ = 0;
  std::size_t map_points_ = 0;  // in the submap after the last update (read back with it)
  std::size_t non_finite_points_ = 0;
  std::size_t upload_bytes_ = 0;  // of the last scan (points, and times when undistorted)
  SE3 last_pose_;                 // of the last map update (the bandwidth measurement's GICP pose)
  StageTimer timer_;
};

std::unique_ptr<pipeline::ScanBackend> make_cuda_scan_backend(const Config& config) {
  return std::make_unique<CudaScanBackend>(config);
}

std::vector<BandwidthSample> measure_kernel_bandwidth(pipeline::ScanBackend& backend, int repeats) {
  auto* cuda_backend = dynamic_cast<CudaScanBackend*>(&backend);
  if (!cuda_backend) throw std::invalid_argument("measure_kernel_bandwidth: the backend is not the CUDA backend");
  return cuda_backend->measure_bandwidth(repeats);
}

}  // namespace farlio::cuda
