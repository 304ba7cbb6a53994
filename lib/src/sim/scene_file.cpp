#include "alvio/sim/scene_file.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "alvio/common/angles.h"
#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/common/resource_path.h"
#include "alvio/sim/seeded_random.h"

namespace alvio::sim {
namespace {

// A YAML mapping together with where it came from, for messages like
// "scene.yaml: objects[3] (box 'pillar'): key 'size' ...". Tracks which keys were
// read so that misspelt keys are reported instead of silently ignored.
class Node {
 public:
  Node(YAML::Node node, std::string where) : node_(std::move(node)), where_(std::move(where)) {}

  const std::string& where() const { return where_; }
  bool has(const std::string& key) const {
    used_.insert(key);
    return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull();
  }
  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw Error(where_ + ": key '" + key + "' " + message);
  }
  YAML::Node raw(const std::string& key) const {
    if (!has(key)) fail(key, "is missing");
    return node_[key];
  }
  double number(const std::string& key) const {
    const YAML::Node n = raw(key);
    try {
      if (!n.IsScalar()) fail(key, "must be a number");
      return n.as<double>();
    } catch (const YAML::Exception&) {
      fail(key, "must be a number, got '" + n.Scalar() + "'");
    }
  }
  double number(const std::string& key, double fallback) const {
    return has(key) ? number(key) : fallback;
  }
  int integer(const std::string& key, int fallback) const {
    if (!has(key)) return fallback;
    const double v = number(key);
    if (v != std::floor(v)) fail(key, "must be an integer");
    return static_cast<int>(v);
  }
  bool boolean(const std::string& key, bool fallback) const {
    if (!has(key)) return fallback;
    try {
      return raw(key).as<bool>();
    } catch (const YAML::Exception&) {
      fail(key, "must be true or false");
    }
  }
  std::string text(const std::string& key) const {
    const YAML::Node n = raw(key);
    if (!n.IsScalar()) fail(key, "must be a string");
    return n.Scalar();
  }
  std::string text(const std::string& key, const std::string& fallback) const {
    return has(key) ? text(key) : fallback;
  }
  std::vector<double> numbers(const std::string& key, std::size_t size) const {
    const YAML::Node n = raw(key);
    if (!n.IsSequence() || n.size() != size)
      fail(key, "must be a list of " + std::to_string(size) + " numbers");
    std::vector<double> out;
    for (std::size_t i = 0; i < size; ++i) {
      try {
        out.push_back(n[i].as<double>());
      } catch (const YAML::Exception&) {
        fail(key, "must be a list of " + std::to_string(size) + " numbers");
      }
    }
    return out;
  }
  Eigen::Vector3d vec3(const std::string& key) const {
    const auto v = numbers(key, 3);
    return {v[0], v[1], v[2]};
  }
  Eigen::Vector3d vec3(const std::string& key, const Eigen::Vector3d& fallback) const {
    return has(key) ? vec3(key) : fallback;
  }
  Eigen::Vector2d vec2(const std::string& key) const {
    const auto v = numbers(key, 2);
    return {v[0], v[1]};
  }
  Node child(const std::string& key) const {
    const YAML::Node n = raw(key);
    if (!n.IsMap()) fail(key, "must be a mapping");
    return Node(n, where_ + ": " + key);
  }
  /// Warn about keys nobody read (probably misspelt).
  void warnUnknownKeys() const {
    if (!node_.IsMap()) return;
    for (const auto& kv : node_) {
      const std::string k = kv.first.as<std::string>();
      if (!used_.count(k)) logWarn(where_, ": unknown key '", k, "' ignored");
    }
  }
  const YAML::Node& yaml() const { return node_; }

 private:
  YAML::Node node_;
  std::string where_;
  mutable std::set<std::string> used_;
};

Eigen::Matrix3d yawMatrix(double yaw_deg) {
  return Eigen::AngleAxisd(yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

Eigen::Matrix3d rotationOf(const Node& o) {
  if (o.has("rotation_deg")) {
    const Eigen::Vector3d r = o.vec3("rotation_deg") * kDegToRad;  // roll, pitch, yaw
    return (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
  return yawMatrix(o.number("yaw_deg", 0.0));
}

// A frame whose z axis is `normal`, x axis horizontal (or world x for horizontal
// planes) and y axis "up" on the plane.
Eigen::Matrix3d planeFrame(Eigen::Vector3d normal, const Node& o) {
  if (normal.norm() < 1e-9) o.fail("normal", "must not be zero");
  normal.normalize();
  Eigen::Vector3d up = o.vec3(
      "up", std::abs(normal.z()) > 0.9 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ());
  Eigen::Vector3d right = up.cross(normal);
  if (right.norm() < 1e-6) o.fail("up", "must not be parallel to the normal");
  right.normalize();
  up = normal.cross(right);
  Eigen::Matrix3d F;
  F << right, up, normal;
  return F;
}

class SceneBuilder {
 public:
  explicit SceneBuilder(Scene* scene) : scene_(scene) {}

  void material(const std::string& name, const Node& m) {
    SceneMaterial mat;
    mat.name = name;
    TextureSpec& t = mat.texture;
    t.pattern = m.text("pattern", t.pattern);
    t.albedo = m.number("albedo", t.albedo);
    t.contrast = m.number("contrast", t.contrast);
    t.texel_m = m.number("texel_m", t.texel_m);
    t.feature_m = m.number("feature_m", t.feature_m);
    t.texture_size = m.integer("texture_size", t.texture_size);
    t.emissive = m.number("emissive", t.emissive);
    t.validate(m.where());
    m.warnUnknownKeys();
    scene_->addMaterial(mat);
  }

  int materialOf(const Node& o, const std::string& key) const {
    const std::string name = o.text(key);
    const int m = scene_->findMaterial(name);
    if (m < 0) o.fail(key, "names an undefined material '" + name + "'");
    return m;
  }

  void box(const Eigen::Vector3d& c, const Eigen::Matrix3d& R, const Eigen::Vector3d& size, int mat,
           int object, const Node& o) {
    if ((size.array() <= 0).any()) o.fail("size", "must be positive in every axis");
    scene_->addBox(c, R, size, mat, object);
  }

  void quad(const Eigen::Vector3d& center, const Eigen::Matrix3d& F, const Eigen::Vector2d& size,
            int mat, int object, bool two_sided) {
    SceneQuad q;
    q.edge_u = F.col(0) * size.x();
    q.edge_v = F.col(1) * size.y();
    q.origin = center - 0.5 * q.edge_u - 0.5 * q.edge_v;
    q.material = mat;
    q.object = object;
    q.two_sided = two_sided;
    scene_->addQuad(q);
  }

  // A box spanning the segment a -> b with a rectangular cross-section.
  void beam(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double width, double height,
            int mat, int object, const Node& o) {
    const Eigen::Vector3d axis = b - a;
    if (axis.norm() < 1e-6) o.fail("to", "must differ from 'from'");
    const Eigen::Vector3d x = axis.normalized();
    Eigen::Vector3d y = Eigen::Vector3d::UnitZ().cross(x);
    if (y.norm() < 1e-6) y = Eigen::Vector3d::UnitY().cross(x);  // vertical beam
    y.normalize();
    const Eigen::Vector3d z = x.cross(y);
    Eigen::Matrix3d R;
    R << x, y, z;
    box(0.5 * (a + b), R, Eigen::Vector3d(axis.norm(), width, height), mat, object, o);
  }

  void object(const Node& o, const Eigen::Vector3d& shift, int index) {
    const std::string type = o.text("type");
    const std::string name = o.text("name", type + "#" + std::to_string(index));
    const int obj = scene_->addObject(name);
    if (type == "box") {
      Eigen::Vector3d center, size;
      if (o.has("min")) {
        const Eigen::Vector3d lo = o.vec3("min"), hi = o.vec3("max");
        center = 0.5 * (lo + hi);
        size = hi - lo;
      } else {
        center = o.vec3("center");
        size = o.vec3("size");
      }
      box(center + shift, rotationOf(o), size, materialOf(o, "material"), obj, o);
    } else if (type == "quad") {
      const Eigen::Matrix3d F = planeFrame(o.vec3("normal"), o);
      quad(o.vec3("center") + shift, F, o.vec2("size"), materialOf(o, "material"), obj,
           o.boolean("two_sided", true));
    } else if (type == "room") {
      room(o, shift, obj);
    } else if (type == "pipe") {
      const double d = o.number("diameter");
      beam(o.vec3("from") + shift, o.vec3("to") + shift, d, d, materialOf(o, "material"), obj, o);
    } else if (type == "frame") {
      frame(o, shift, obj);
    } else if (type == "shelf") {
      shelf(o, shift, obj, index);
    } else if (type == "tray") {
      tray(o, shift, obj);
    } else if (type == "railing") {
      railing(o, shift, obj);
    } else if (type == "stairs") {
      stairs(o, shift, obj);
    } else {
      o.fail("type", "is unknown: '" + type +
                         "' (box, quad, room, pipe, frame, shelf, tray, railing, stairs)");
    }
  }

 private:
  // Floor, ceiling and four walls: boxes whose inner faces are at min/max.
  void room(const Node& o, const Eigen::Vector3d& shift, int obj) {
    const Eigen::Vector3d lo = o.vec3("min") + shift, hi = o.vec3("max") + shift;
    const double t = o.number("thickness", 0.3);
    const int floor = materialOf(o, "floor"), ceiling = materialOf(o, "ceiling");
    const int walls = materialOf(o, "walls");
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    const Eigen::Vector3d c = 0.5 * (lo + hi), s = hi - lo;
    if ((s.array() <= 0).any()) o.fail("max", "must be greater than 'min' in every axis");
    box({c.x(), c.y(), lo.z() - t / 2}, I, {s.x() + 2 * t, s.y() + 2 * t, t}, floor, obj, o);
    box({c.x(), c.y(), hi.z() + t / 2}, I, {s.x() + 2 * t, s.y() + 2 * t, t}, ceiling, obj, o);
    box({lo.x() - t / 2, c.y(), c.z()}, I, {t, s.y(), s.z()}, walls, obj, o);
    box({hi.x() + t / 2, c.y(), c.z()}, I, {t, s.y(), s.z()}, walls, obj, o);
    box({c.x(), lo.y() - t / 2, c.z()}, I, {s.x() + 2 * t, t, s.z()}, walls, obj, o);
    box({c.x(), hi.y() + t / 2, c.z()}, I, {s.x() + 2 * t, t, s.z()}, walls, obj, o);
  }

  // Door or window frame: posts and bars around an opening, optionally with a
  // panel (door leaf, glass) inside; a door has no bottom bar.
  void frame(const Node& o, const Eigen::Vector3d& shift, int obj) {
    const Eigen::Matrix3d F = planeFrame(o.vec3("normal"), o);
    const Eigen::Vector3d c = o.vec3("center") + shift;
    const Eigen::Vector2d size = o.vec2("size");  // outer width, height
    const double bar = o.number("bar", 0.08), depth = o.number("depth", 0.06);
    const int mat = materialOf(o, "material");
    const bool door = o.boolean("door", false);
    const Eigen::Vector3d r = F.col(0), u = F.col(1), n = F.col(2);
    const double w = size.x(), h = size.y();
    // Posts.
    for (int side : {-1, 1}) box(c + side * (w - bar) / 2 * r, F, {bar, h, depth}, mat, obj, o);
    // Top and bottom bars between the posts.
    box(c + (h - bar) / 2 * u, F, {w - 2 * bar, bar, depth}, mat, obj, o);
    if (!door) box(c - (h - bar) / 2 * u, F, {w - 2 * bar, bar, depth}, mat, obj, o);
    const double inner_w = w - 2 * bar, inner_h = door ? h - bar : h - 2 * bar;
    const Eigen::Vector3d inner_c = c - (door ? bar / 2 : 0.0) * u;
    if (o.has("panes")) {
      // Mullions (window bars) dividing the opening into cols x rows panes.
      const auto panes = o.numbers("panes", 2);
      const int cols = static_cast<int>(panes[0]), rows = static_cast<int>(panes[1]);
      if (cols < 1 || rows < 1) o.fail("panes", "must be two counts >= 1");
      const double m = 0.5 * bar;
      for (int i = 1; i < cols; ++i)
        box(inner_c + (-inner_w / 2 + i * inner_w / cols) * r, F, {m, inner_h, 0.6 * depth}, mat,
            obj, o);
      for (int j = 1; j < rows; ++j)
        box(inner_c + (-inner_h / 2 + j * inner_h / rows) * u, F, {inner_w, m, 0.6 * depth}, mat,
            obj, o);
    }
    if (o.has("fill")) {
      // The panel sits recessed by half the frame depth.
      quad(inner_c - 0.25 * depth * n, F, {inner_w, inner_h}, materialOf(o, "fill"), obj, false);
    }
  }

  // Storage rack: uprights every <= 2.7 m, boards at `levels` heights, and goods
  // (boxes of random size) on the boards.
  void shelf(const Node& o, const Eigen::Vector3d& shift, int obj, int index) {
    const Eigen::Vector3d base = o.vec3("center") + shift;  // floor centre
    const Eigen::Vector3d size = o.vec3("size");            // length, depth, height
    const Eigen::Matrix3d R = yawMatrix(o.number("yaw_deg", 0.0));
    const int levels = o.integer("levels", 4);
    const int mat = materialOf(o, "material");
    const int goods = o.has("goods") ? materialOf(o, "goods") : -1;
    const double post = 0.08, board = 0.04;
    const int bays = std::max(1, static_cast<int>(std::ceil(size.x() / 2.7)));
    const Eigen::Vector3d x = R.col(0), y = R.col(1), z = R.col(2);
    for (int i = 0; i <= bays; ++i)
      for (int side : {-1, 1}) {
        const double px = -size.x() / 2 + post / 2 + i * (size.x() - post) / bays;
        const Eigen::Vector3d c =
            base + px * x + side * (size.y() - post) / 2 * y + size.z() / 2 * z;
        box(c, R, {post, post, size.z()}, mat, obj, o);
      }
    SeededRandom rng(mixSeed(scene_->texture_seed, 0x5e1f, index));
    for (int l = 0; l < levels; ++l) {
      const double zl = 0.15 + l * (size.z() - 0.3) / std::max(1, levels - 1);
      box(base + (zl - board / 2) * z, R, {size.x(), size.y(), board}, mat, obj, o);
      if (goods < 0 || l == levels - 1) continue;
      // Boxes on the board, left to right with random gaps, below the next board.
      const double clear = (size.z() - 0.3) / std::max(1, levels - 1) - board - 0.05;
      double px = -size.x() / 2 + post + 0.05;
      while (true) {
        const double bw = rng.uniform(0.3, 0.9), bd = rng.uniform(0.4, 0.95) * size.y();
        const double bh = rng.uniform(0.35, 1.0) * clear;
        if (px + bw > size.x() / 2 - post - 0.05) break;
        if (rng.uniform() < 0.8) {
          const Eigen::Vector3d c =
              base + (px + bw / 2) * x + rng.uniform(-0.05, 0.05) * y + (zl + bh / 2) * z;
          box(c, R * yawMatrix(rng.uniform(-4, 4)), {bw, bd, bh}, goods, obj, o);
        }
        px += bw + rng.uniform(0.05, 0.4);
      }
    }
  }

  // Cable tray: a U-shaped channel (bottom and two sides) along a horizontal run.
  void tray(const Node& o, const Eigen::Vector3d& shift, int obj) {
    const Eigen::Vector3d a = o.vec3("from") + shift, b = o.vec3("to") + shift;
    const double w = o.number("width", 0.3), h = o.number("height", 0.08), t = 0.01;
    const int mat = materialOf(o, "material");
    const Eigen::Vector3d x = (b - a).normalized();
    Eigen::Vector3d y = Eigen::Vector3d::UnitZ().cross(x);
    if (y.norm() < 1e-6) o.fail("to", "a tray must run horizontally");
    y.normalize();
    beam(a, b, w, t, mat, obj, o);
    for (int side : {-1, 1}) {
      const Eigen::Vector3d off = side * (w / 2 - t / 2) * y + Eigen::Vector3d(0, 0, h / 2);
      beam(a + off, b + off, t, h, mat, obj, o);
    }
  }

  // Guard rail along a horizontal run: posts, a top and a middle rail, a toe board.
  void railing(const Node& o, const Eigen::Vector3d& shift, int obj) {
    const Eigen::Vector3d a = o.vec3("from") + shift, b = o.vec3("to") + shift;
    const double h = o.number("height", 1.1), d = o.number("diameter", 0.045);
    const double spacing = o.number("post_spacing", 1.5);
    const int mat = materialOf(o, "material");
    const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
    const int posts = std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing)));
    for (int i = 0; i <= posts; ++i) {
      const Eigen::Vector3d p = a + (b - a) * (static_cast<double>(i) / posts);
      beam(p, p + up * h, d, d, mat, obj, o);
    }
    beam(a + up * (h + d / 2), b + up * (h + d / 2), d, d, mat, obj, o);
    beam(a + up * (h / 2), b + up * (h / 2), 0.8 * d, 0.8 * d, mat, obj, o);
    beam(a + up * 0.05, b + up * 0.05, 0.02, 0.1, mat, obj, o);
  }

  // A straight flight of steps from `from` (bottom, front edge centre, on the floor)
  // up to `to` (top landing height), with side stringers.
  void stairs(const Node& o, const Eigen::Vector3d& shift, int obj) {
    const Eigen::Vector3d a = o.vec3("from") + shift, b = o.vec3("to") + shift;
    const double width = o.number("width", 1.0);
    const int mat = materialOf(o, "material");
    Eigen::Vector3d run = b - a;
    const double rise = run.z();
    run.z() = 0;
    if (rise <= 0 || run.norm() < 0.1) o.fail("to", "must be higher than and away from 'from'");
    const int steps = std::max(1, static_cast<int>(std::lround(rise / 0.19)));
    const Eigen::Vector3d x = run.normalized();
    Eigen::Matrix3d R;
    R << x, Eigen::Vector3d::UnitZ().cross(x), Eigen::Vector3d::UnitZ();
    const double step_run = run.norm() / steps, step_rise = rise / steps;
    for (int i = 0; i < steps; ++i) {
      const Eigen::Vector3d c =
          a + x * ((i + 0.5) * step_run) + Eigen::Vector3d(0, 0, (i + 1) * step_rise - 0.02);
      box(c, R, {step_run + 0.03, width, 0.04}, mat, obj, o);
    }
    for (int side : {-1, 1}) {
      const Eigen::Vector3d off = R.col(1) * (side * (width / 2 + 0.03));
      beam(a + off + Eigen::Vector3d(0, 0, 0.1), b + off + Eigen::Vector3d(0, 0, 0.05), 0.04, 0.25,
           mat, obj, o);
    }
  }

  Scene* scene_;
};

SceneFile parseRoot(const YAML::Node& root, const std::string& name) {
  if (!root.IsMap()) throw Error(name + ": expected a mapping at the top level");
  const Node top(root, name);
  SceneFile out;
  Scene& scene = out.scene;
  scene.name = top.text("name", std::filesystem::path(name).stem().string());
  scene.texture_seed = static_cast<uint64_t>(top.integer("texture_seed", 1));

  if (top.has("lighting")) {
    const Node l = top.child("lighting");
    scene.lighting.ambient = l.number("ambient", scene.lighting.ambient);
    scene.lighting.falloff_m = l.number("falloff_m", scene.lighting.falloff_m);
    if (l.has("directional")) {
      const YAML::Node list = l.raw("directional");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const Node d(list[i], l.where() + ".directional[" + std::to_string(i) + "]");
        DirectionalLight light;
        light.direction = d.vec3("direction").normalized();
        light.intensity = d.number("intensity");
        d.warnUnknownKeys();
        scene.lighting.directional.push_back(light);
      }
    }
    if (l.has("points")) {
      const YAML::Node list = l.raw("points");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const Node p(list[i], l.where() + ".points[" + std::to_string(i) + "]");
        PointLight light;
        light.position = p.vec3("position");
        light.intensity = p.number("intensity");
        const Eigen::Vector3d step = p.vec3("repeat_step", Eigen::Vector3d::Zero());
        const int count = p.integer("repeat", 1);
        p.warnUnknownKeys();
        for (int k = 0; k < count; ++k) {
          scene.lighting.points.push_back(light);
          light.position += step;
        }
      }
    }
    l.warnUnknownKeys();
  }

  const YAML::Node materials = top.raw("materials");
  if (!materials.IsMap()) top.fail("materials", "must be a mapping of name: {pattern: ...}");
  SceneBuilder builder(&scene);
  for (const auto& kv : materials) {
    const std::string mname = kv.first.as<std::string>();
    builder.material(mname, Node(kv.second, name + ": materials." + mname));
  }

  const YAML::Node objects = top.raw("objects");
  if (!objects.IsSequence()) top.fail("objects", "must be a list");
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const YAML::Node item = objects[i];
    std::string where = name + ": objects[" + std::to_string(i) + "]";
    if (item.IsMap()) {
      const YAML::Node& map = item;
      const YAML::Node object_name = map["name"];
      if (object_name.IsDefined() && object_name.IsScalar())
        where += " ('" + object_name.Scalar() + "')";
    }
    const Node o(item, where);
    int count = 1;
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    if (o.has("repeat")) {
      const Node r = o.child("repeat");
      count = r.integer("count", 1);
      step = r.vec3("step");
      if (count < 1) r.fail("count", "must be >= 1");
      r.warnUnknownKeys();
    }
    for (int k = 0; k < count; ++k) builder.object(o, k * step, static_cast<int>(i) * 1000 + k);
    o.warnUnknownKeys();
  }

  if (top.has("paths")) {
    const Node p = top.child("paths");
    if (p.has("figure8")) {
      const Node f = p.child("figure8");
      auto& o = out.figure_eight;
      o.center = f.vec3("center", o.center);
      o.half_length_m = f.number("half_length", o.half_length_m);
      o.half_width_m = f.number("half_width", o.half_width_m);
      o.height_amplitude_m = f.number("height_amplitude", o.height_amplitude_m);
      o.lap_period_s = f.number("lap_period", o.lap_period_s);
      f.warnUnknownKeys();
    }
    if (p.has("corridor")) {
      const Node c = p.child("corridor");
      auto& o = out.corridor;
      o.start = c.vec3("start", o.start);
      o.length_m = c.number("length", o.length_m);
      o.speed_mps = c.number("speed", o.speed_mps);
      o.look_around_deg = c.number("look_around_deg", o.look_around_deg);
      c.warnUnknownKeys();
    }
    p.warnUnknownKeys();
  }
  top.warnUnknownKeys();
  scene.finalize();
  return out;
}

}  // namespace

SceneFile parseSceneText(const std::string& text, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(name + ": YAML syntax error at line " + std::to_string(e.mark.line + 1) + ": " +
                e.msg);
  }
  return parseRoot(root, name);
}

SceneFile loadSceneFile(const std::string& path) {
  const std::string file = resolveScenePath(path);
  std::ifstream in(file);
  if (!in) throw Error("cannot open scene file '" + file + "'");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parseSceneText(buffer.str(), file);
}

std::string resolveScenePath(const std::string& name_or_path) {
  if (std::filesystem::exists(name_or_path)) return name_or_path;
  if (name_or_path.find('/') == std::string::npos) {
    const std::string file =
        name_or_path.size() > 5 && name_or_path.substr(name_or_path.size() - 5) == ".yaml"
            ? name_or_path
            : name_or_path + ".yaml";
    try {
      return findPackageFile("config/scenes/" + file);
    } catch (const Error&) {
    }
  }
  throw Error("scene file '" + name_or_path +
              "' not found (give a path, or the name of a scene in config/scenes/)");
}

std::string defaultScenePath() {
  return findPackageFile("config/scenes/machine_hall.yaml");
}

}  // namespace alvio::sim
