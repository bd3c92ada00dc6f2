#include "semap/mapping/training_data.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "fast_floor.hpp"
#include "voxel_grouping.hpp"

namespace semap::mapping {

namespace {

// Only called for keyable points, so the fast floor is exact.
common::BlockIndex voxel_of(const Eigen::Vector3f& p, float inv_res) {
  return {detail::fast_floor(p.x() * inv_res), detail::fast_floor(p.y() * inv_res),
          detail::fast_floor(p.z() * inv_res)};
}

// Grid coordinates beyond +-2^20 voxels (or NaN) cannot be keyed; reject before flooring.
bool keyable(const Eigen::Vector3f& p, float inv_res) {
  constexpr float kLimit = static_cast<float>(1 << 20) - 1.0f;
  return p.allFinite() && (p.cwiseAbs() * inv_res).maxCoeff() < kLimit;
}

// Centroid accumulator of one voxel.
struct Centroid {
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  std::uint32_t count = 0;
};

void check_cloud(const common::LabeledCloud& cloud, int k) {
  if (cloud.has_probabilities()) {
    if (cloud.num_classes != k) {
      throw std::invalid_argument("cloud has " + std::to_string(cloud.num_classes) +
                                  " classes, map has " + std::to_string(k));
    }
    if (cloud.probabilities.size() != cloud.points.size() * static_cast<std::size_t>(k)) {
      throw std::invalid_argument("cloud has " + std::to_string(cloud.probabilities.size()) +
                                  " probabilities for " + std::to_string(cloud.points.size()) +
                                  " points and " + std::to_string(k) + " classes");
    }
  } else if (cloud.labels.size() != cloud.points.size()) {
    throw std::invalid_argument("cloud has " + std::to_string(cloud.labels.size()) +
                                " labels for " + std::to_string(cloud.points.size()) + " points");
  }
}

// Items per chunk of the parallel per-point passes; a toy scan (3.5k points) stays one chunk.
constexpr std::size_t kGrain = 8192;

// Averages the hits per ds_res voxel into `out` (positions, labels, probabilities).
void downsample_hits(const common::LabeledCloud& cloud, const Eigen::Vector3f& origin,
                     const MapParams& params, TrainingSet& out) {
  const int k = params.num_classes;
  const float inv_res = 1.0f / params.ds_res;
  const bool soft = cloud.has_probabilities();
  const float max_range2 = params.max_range * params.max_range;
  const std::size_t n = cloud.size();
  // Per point: 0 kept, 1 rejected, 2 beyond max_range; and its voxel. Independent per
  // point, so computed in parallel.
  std::vector<std::uint8_t> status(n);
  std::vector<common::BlockIndex> keys(n);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, kGrain),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const Eigen::Vector3f& p = cloud.points[i];
          if (!keyable(p, inv_res) || (!soft && cloud.labels[i] >= k)) {
            status[i] = 1;
          } else if (params.max_range > 0.0f && (p - origin).squaredNorm() > max_range2) {
            status[i] = 2;
          } else {
            status[i] = 0;
            keys[i] = voxel_of(p, inv_res);
          }
        }
      });
  for (const std::uint8_t s : status) {
    out.rejected += s == 1 ? 1 : 0;
    out.out_of_range += s == 2 ? 1 : 0;
  }
  detail::VoxelGrouping grouping;
  grouping.group(keys, status);
  const auto voxel_of_point = grouping.voxel_of();
  const std::size_t voxels = grouping.voxels();
  std::vector<Centroid> centroids(voxels);
  // Per voxel: label counts (hard) or probability sums (soft), K floats each.
  std::vector<float> votes(voxels * static_cast<std::size_t>(k), 0.0f);
  // Input order per voxel, as a serial pass would sum; voxel sets in parallel.
  grouping.for_each_item([&](std::size_t i) {
    const std::uint32_t id = voxel_of_point[i];
    centroids[id].sum += cloud.points[i];
    ++centroids[id].count;
    float* v = votes.data() + static_cast<std::size_t>(id) * k;
    if (soft) {
      const float* prob = cloud.probabilities.data() + i * static_cast<std::size_t>(k);
      for (int c = 0; c < k; ++c) v[c] += prob[c];
    } else {
      v[cloud.labels[i]] += 1.0f;
    }
  });
  out.points.reserve(voxels);
  out.labels.reserve(voxels);
  if (soft) out.probabilities.reserve(voxels * static_cast<std::size_t>(k));
  for (std::size_t id = 0; id < voxels; ++id) {
    const Centroid& c = centroids[id];
    const float* v = votes.data() + id * static_cast<std::size_t>(k);
    out.points.push_back(c.sum / static_cast<float>(c.count));
    if (soft) {
      out.labels.push_back(TrainingSet::kSoft);
      for (int j = 0; j < k; ++j) out.probabilities.push_back(v[j] / static_cast<float>(c.count));
    } else {
      int best = 0;
      for (int j = 1; j < k; ++j) best = v[j] > v[best] ? j : best;
      out.labels.push_back(best);
    }
  }
  out.num_hits = out.points.size();
}

// Adds the origin and the free samples of every hit beam, averaged per ds_res voxel.
void add_free_samples(const Eigen::Vector3f& origin, const MapParams& params, TrainingSet& out) {
  const float inv_res = 1.0f / params.ds_res;
  const float step = params.free_res;
  // Samples lie between the origin and keyable hits, so a keyable origin keeps them keyable.
  if (!keyable(origin, inv_res)) return;
  const std::size_t hits = out.num_hits;
  // Samples per beam: at step, 2 step, ... while at least one step short of the hit.
  std::vector<std::uint32_t> first(hits + 1, 0);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, hits, kGrain),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const float length = (out.points[i] - origin).norm();
          first[i + 1] =
              length > step ? static_cast<std::uint32_t>(std::floor((length - step) / step)) : 0;
        }
      });
  // The origin is item 0; beam i's samples follow at first[i] + 1 ...
  for (std::size_t i = 0; i < hits; ++i) first[i + 1] += first[i];
  const std::size_t items = std::size_t{first[hits]} + 1;
  std::vector<Eigen::Vector3f> samples(items);
  std::vector<common::BlockIndex> keys(items);
  samples[0] = origin;
  keys[0] = voxel_of(origin, inv_res);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, hits, kGrain / 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const std::uint32_t count = first[i + 1] - first[i];
                        if (count == 0) continue;
                        const Eigen::Vector3f ray = out.points[i] - origin;
                        const Eigen::Vector3f dir = ray / ray.norm();
                        for (std::uint32_t s = 1; s <= count; ++s) {
                          const std::size_t j = first[i] + s;
                          samples[j] = origin + dir * (step * static_cast<float>(s));
                          keys[j] = voxel_of(samples[j], inv_res);
                        }
                      }
                    });
  detail::VoxelGrouping grouping;
  grouping.group(keys, {});
  const auto voxel_of_sample = grouping.voxel_of();
  std::vector<Centroid> centroids(grouping.voxels());
  grouping.for_each_item([&](std::size_t j) {
    Centroid& c = centroids[voxel_of_sample[j]];
    c.sum += samples[j];
    ++c.count;
  });
  out.points.reserve(out.points.size() + centroids.size());
  out.labels.reserve(out.labels.size() + centroids.size());
  for (const Centroid& c : centroids) {
    out.points.push_back(c.sum / static_cast<float>(c.count));
    out.labels.push_back(0);
  }
}

}  // namespace

TrainingSet build_training_set(const common::LabeledCloud& cloud, const Eigen::Vector3f& origin,
                               const MapParams& params) {
  check_cloud(cloud, params.num_classes);
  TrainingSet out;
  out.num_classes = params.num_classes;
  downsample_hits(cloud, origin, params, out);
  add_free_samples(origin, params, out);
  return out;
}

}  // namespace semap::mapping
