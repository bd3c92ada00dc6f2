#include "semap/mapping/training_data.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "semap/mapping/voxel_hash_map.hpp"

namespace semap::mapping {

namespace {

BlockIndex voxel_of(const Eigen::Vector3f& p, float inv_res) {
  return {static_cast<std::int32_t>(std::floor(p.x() * inv_res)),
          static_cast<std::int32_t>(std::floor(p.y() * inv_res)),
          static_cast<std::int32_t>(std::floor(p.z() * inv_res))};
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

// Averages the hits per ds_res voxel into `out` (positions, labels, probabilities).
void downsample_hits(const common::LabeledCloud& cloud, const Eigen::Vector3f& origin,
                     const MapParams& params, TrainingSet& out) {
  const int k = params.num_classes;
  const float inv_res = 1.0f / params.ds_res;
  const bool soft = cloud.has_probabilities();
  const float max_range2 = params.max_range * params.max_range;
  VoxelHashMap voxels(cloud.size() / 2 + 16);
  std::vector<Centroid> centroids;
  // Per voxel: label counts (hard) or probability sums (soft), K floats each.
  std::vector<float> votes;
  centroids.reserve(cloud.size() / 2 + 16);
  votes.reserve((cloud.size() / 2 + 16) * static_cast<std::size_t>(k));
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (!keyable(p, inv_res) || (!soft && cloud.labels[i] >= k)) {
      ++out.rejected;
      continue;
    }
    if (params.max_range > 0.0f && (p - origin).squaredNorm() > max_range2) {
      ++out.out_of_range;
      continue;
    }
    const std::uint32_t id = voxels.insert(voxel_of(p, inv_res));
    if (id == centroids.size()) {
      centroids.emplace_back();
      votes.resize(votes.size() + static_cast<std::size_t>(k), 0.0f);
    }
    centroids[id].sum += p;
    ++centroids[id].count;
    float* v = votes.data() + static_cast<std::size_t>(id) * k;
    if (soft) {
      const float* prob = cloud.probabilities.data() + i * static_cast<std::size_t>(k);
      for (int c = 0; c < k; ++c) v[c] += prob[c];
    } else {
      v[cloud.labels[i]] += 1.0f;
    }
  }
  out.points.reserve(centroids.size());
  out.labels.reserve(centroids.size());
  if (soft) out.probabilities.reserve(centroids.size() * static_cast<std::size_t>(k));
  for (std::size_t id = 0; id < centroids.size(); ++id) {
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
  VoxelHashMap voxels(out.num_hits * 4 + 16);
  std::vector<Centroid> centroids;
  auto add = [&](const Eigen::Vector3f& p) {
    const std::uint32_t id = voxels.insert(voxel_of(p, inv_res));
    if (id == centroids.size()) centroids.emplace_back();
    centroids[id].sum += p;
    ++centroids[id].count;
  };
  // Samples lie between the origin and keyable hits, so a keyable origin keeps them keyable.
  if (!keyable(origin, inv_res)) return;
  add(origin);
  for (std::size_t i = 0; i < out.num_hits; ++i) {
    const Eigen::Vector3f ray = out.points[i] - origin;
    const float length = ray.norm();
    if (!(length > step)) continue;
    const Eigen::Vector3f dir = ray / length;
    // Samples at step, 2 step, ... while at least one step short of the hit.
    const int samples = static_cast<int>(std::floor((length - step) / step));
    for (int s = 1; s <= samples; ++s) add(origin + dir * (step * static_cast<float>(s)));
  }
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
