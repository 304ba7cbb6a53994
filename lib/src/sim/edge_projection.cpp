#include "alvio/sim/edge_projection.h"

#include <cstdio>

#include "alvio/io/text_table_reader.h"
#include "alvio/io/trajectory_io.h"

namespace alvio::sim {

std::vector<VisibleEdge> projectVisibleEdges(const Scene& scene, const CameraModel& camera,
                                             const Eigen::Isometry3d& T_w_c,
                                             const EdgeProjectionOptions& o) {
  const Eigen::Isometry3d T_c_w = T_w_c.inverse();
  const Eigen::Vector3d centre = T_w_c.translation();
  const int n = std::max(2, o.samples_per_edge);
  std::vector<VisibleEdge> out;
  for (const SceneEdge& e : scene.edges()) {
    // Cheap rejection: both ends behind the camera.
    if ((T_c_w * e.a).z() <= 0 && (T_c_w * e.b).z() <= 0) continue;
    int best_first = -1, best_last = -1, run_first = -1;
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector3d p = e.a + (e.b - e.a) * (static_cast<double>(i) / n);
      Eigen::Vector2d px;
      // A point on an edge touches its own surfaces: allow 2 mm (and 0.1 %) of slack.
      const double tolerance = 2e-3 + 1e-3 * (p - centre).norm();
      const bool seen = camera.project(T_c_w * p, &px) && camera.inImage(px, o.border_px) &&
                        scene.isVisible(p, centre, tolerance);
      if (seen && run_first < 0) run_first = i;
      if ((!seen || i == n) && run_first >= 0) {
        const int last = seen ? i : i - 1;
        if (best_first < 0 || last - run_first > best_last - best_first) {
          best_first = run_first;
          best_last = last;
        }
        run_first = -1;
      }
    }
    if (best_first < 0 || best_last == best_first) continue;
    VisibleEdge v;
    v.edge_id = e.id;
    v.a_w = e.a + (e.b - e.a) * (static_cast<double>(best_first) / n);
    v.b_w = e.a + (e.b - e.a) * (static_cast<double>(best_last) / n);
    camera.project(T_c_w * v.a_w, &v.a_px);
    camera.project(T_c_w * v.b_w, &v.b_px);
    v.visible_fraction = static_cast<double>(best_last - best_first) / n;
    if ((v.b_px - v.a_px).norm() < o.min_length_px) continue;
    out.push_back(v);
  }
  return out;
}

void writeSceneEdgesCsv(const std::string& path, const Scene& scene) {
  std::string text = "#id,ax,ay,az,bx,by,bz,object\n";
  char buf[256];
  for (const SceneEdge& e : scene.edges()) {
    std::snprintf(buf, sizeof(buf), "%d,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,", e.id, e.a.x(), e.a.y(),
                  e.a.z(), e.b.x(), e.b.y(), e.b.z());
    text += buf;
    text += scene.objectNames()[e.object] + "\n";
  }
  writeFileAtomically(path, text);
}

std::vector<SceneEdge> readSceneEdgesCsv(const std::string& path) {
  TextTableReader reader(path);
  std::vector<SceneEdge> edges;
  std::vector<std::string> f;
  while (reader.next(&f)) {
    if (f.size() < 7) reader.fail("expected id,ax,ay,az,bx,by,bz,object");
    SceneEdge e;
    e.id = static_cast<int>(reader.toInt64(f[0], 1));
    for (int i = 0; i < 3; ++i) {
      e.a[i] = reader.toDouble(f[1 + i], 2 + i);
      e.b[i] = reader.toDouble(f[4 + i], 5 + i);
    }
    e.object = -1;
    edges.push_back(e);
  }
  return edges;
}

}  // namespace alvio::sim
