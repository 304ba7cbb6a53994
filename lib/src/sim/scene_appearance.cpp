#include "alvio/sim/scene_appearance.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include "alvio/sim/parallel_for.h"
#include "alvio/sim/seeded_random.h"

namespace alvio::sim {
namespace {

// Irradiance at p (normal n) from the scene's lights, with shadow rays.
float irradianceAt(const Scene& scene, const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                   const AppearanceOptions& o, SeededRandom& rng) {
  const SceneLighting& L = scene.lighting;
  const Eigen::Vector3d origin = p + 2e-3 * n;
  double ambient = L.ambient;
  if (o.occlusion_rays > 0) {
    // Cosine-weighted hemisphere rays; blocked within 1.5 m darkens the ambient term.
    const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    double open = 0;
    for (int k = 0; k < o.occlusion_rays; ++k) {
      const double r = std::sqrt((k + rng.uniform()) / o.occlusion_rays);
      const double phi = 2 * M_PI * rng.uniform();
      const Eigen::Vector3d d =
          r * std::cos(phi) * t1 + r * std::sin(phi) * t2 + std::sqrt(1 - r * r) * n;
      const auto hit = scene.intersect(origin, d, 1.5);
      open += hit ? std::min(1.0, hit->t / 1.5) : 1.0;
    }
    ambient *= 0.35 + 0.65 * open / o.occlusion_rays;
  }
  double e = ambient;
  for (const DirectionalLight& d : L.directional) {
    const double c = -n.dot(d.direction);
    if (c <= 0) continue;
    if (o.shadows && scene.intersect(origin, -d.direction, 100.0)) continue;
    e += d.intensity * c;
  }
  for (const PointLight& l : L.points) {
    const Eigen::Vector3d to = l.position - p;
    const double dist = to.norm();
    const double c = n.dot(to) / dist;
    if (c <= 0) continue;
    if (o.shadows && scene.intersect(origin, to / dist, dist - 0.05)) continue;
    e += l.intensity * c / (1 + (dist / L.falloff_m) * (dist / L.falloff_m));
  }
  return static_cast<float>(e);
}

}  // namespace

float SceneAppearance::LightMap::irradiance(bool back_side, float a, float b) const {
  const std::vector<float>& m = back_side ? back : front;
  // Samples sit at cell centres; clamp to the outer half cells.
  const float x = std::clamp(a * nu - 0.5f, 0.0f, static_cast<float>(nu - 1));
  const float y = std::clamp(b * nv - 0.5f, 0.0f, static_cast<float>(nv - 1));
  const int i = std::min(static_cast<int>(x), nu - 2 < 0 ? 0 : nu - 2);
  const int j = std::min(static_cast<int>(y), nv - 2 < 0 ? 0 : nv - 2);
  const int i1 = std::min(i + 1, nu - 1), j1 = std::min(j + 1, nv - 1);
  const float fx = x - i, fy = y - j;
  const float top = m[j * nu + i] + fx * (m[j * nu + i1] - m[j * nu + i]);
  const float bottom = m[j1 * nu + i] + fx * (m[j1 * nu + i1] - m[j1 * nu + i]);
  return top + fy * (bottom - top);
}

SceneAppearance::SceneAppearance(const Scene& scene, const AppearanceOptions& o) {
  const auto& quads = scene.quads();
  const auto& materials = scene.materials();
  const uint64_t seed = mixSeed(scene.texture_seed, o.seed);

  // One shared tiling texture per material, plus one per quad for unique patterns.
  struct Job {
    TextureSpec spec;
    int w, h;
    uint64_t seed;
    bool repeat;
  };
  std::vector<Job> jobs;
  std::vector<int> material_texture(materials.size(), -1);
  for (std::size_t m = 0; m < materials.size(); ++m) {
    const TextureSpec& s = materials[m].texture;
    if (s.uniquePerSurface()) continue;
    material_texture[m] = static_cast<int>(jobs.size());
    const int size = s.pattern == "plain" ? 8 : s.texture_size;
    jobs.push_back({s, size, size, mixSeed(seed, m), true});
  }
  mappings_.resize(quads.size());
  SeededRandom rng(mixSeed(seed, 0xabcdef));
  for (std::size_t i = 0; i < quads.size(); ++i) {
    const SceneQuad& q = quads[i];
    const TextureSpec& s = materials[q.material].texture;
    Mapping& mp = mappings_[i];
    mp.swap = std::abs(q.edge_u.z()) > std::abs(q.edge_v.z()) + 1e-9;
    mp.inv_texel = static_cast<float>(1.0 / s.texel_m);
    mp.emissive = static_cast<float>(s.emissive);
    if (s.uniquePerSurface()) {
      const double w_m = (mp.swap ? q.edge_v : q.edge_u).norm();
      const double h_m = (mp.swap ? q.edge_u : q.edge_v).norm();
      const int w = std::clamp(static_cast<int>(std::lround(w_m / s.texel_m)), 8, 2048);
      const int h = std::clamp(static_cast<int>(std::lround(h_m / s.texel_m)), 8, 2048);
      mp.texture = static_cast<int>(jobs.size());
      jobs.push_back({s, w, h, mixSeed(seed, 0x9000 + i), false});
    } else {
      mp.texture = material_texture[q.material];
      const double period = s.texture_size * s.texel_m;
      mp.offset_x = static_cast<float>(rng.uniform(0, period));
      mp.offset_y = static_cast<float>(rng.uniform(0, period));
    }
  }
  textures_.resize(jobs.size());
  parallelFor(static_cast<int>(jobs.size()), o.threads, [&](int j) {
    const Job& job = jobs[j];
    textures_[j] =
        Texture(generateTextureImage(job.spec, job.w, job.h, o.texture_density, job.seed),
                job.spec.texel_m, job.repeat);
  });

  // Light maps, each sample seeded by its quad so threads do not change the result.
  light_maps_.resize(quads.size());
  parallelFor(static_cast<int>(quads.size()), o.threads, [&](int i) {
    const SceneQuad& q = quads[i];
    LightMap& lm = light_maps_[i];
    lm.nu = std::clamp(static_cast<int>(std::ceil(q.edge_u.norm() / o.light_map_cell_m)), 2, 512);
    lm.nv = std::clamp(static_cast<int>(std::ceil(q.edge_v.norm() / o.light_map_cell_m)), 2, 512);
    const Eigen::Vector3d n = q.normal();
    SeededRandom sample_rng(mixSeed(seed, 0x11, i));
    lm.front.resize(lm.nu * lm.nv);
    if (q.two_sided) lm.back.resize(lm.nu * lm.nv);
    for (int v = 0; v < lm.nv; ++v)
      for (int u = 0; u < lm.nu; ++u) {
        const Eigen::Vector3d p =
            q.origin + q.edge_u * ((u + 0.5) / lm.nu) + q.edge_v * ((v + 0.5) / lm.nv);
        lm.front[v * lm.nu + u] = irradianceAt(scene, p, n, o, sample_rng);
        if (q.two_sided) lm.back[v * lm.nu + u] = irradianceAt(scene, p, -n, o, sample_rng);
      }
  });
}

}  // namespace alvio::sim
