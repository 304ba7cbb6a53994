// Geometric exactness of the renderer: scene corners and edges projected with
// the ground-truth pose (body pose composed with T_b_c, through the EuRoC
// radial-tangential model) land on the rendered ones to within 0.5 px.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "alvio/config/config.h"
#include "alvio/sim/camera_simulator.h"
#include "alvio/sim/scene_appearance.h"
#include "alvio/sim/texture_edges.h"

using namespace alvio;
using namespace alvio::sim;

namespace {

struct TestView {
  Config config = Config::load(Config::defaultPath());
  std::unique_ptr<CameraModel> camera = CameraModel::create(config.camera);
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_w_c() const { return T_w_b * config.camera.T_b_c; }
  TestView() {
    // The first pose of EuRoC MH_05's ground truth.
    T_w_b.linear() = Eigen::Quaterniond(0.238261, -0.757610, -0.348629, -0.497711)
                         .normalized()
                         .toRotationMatrix();
    T_w_b.translation() = Eigen::Vector3d(4.460675, -1.680515, 0.579614);
  }
};

TextureSpec plainWhite() {
  TextureSpec t;
  t.pattern = "plain";
  t.albedo = 0.9;
  return t;
}

// White rectangles at 2..5 m in front of the camera, spread over the image (the
// corners near the border are displaced tens of pixels by the lens distortion),
// tilted, in a dark room lit only by ambient light. `target` is their texture.
Scene makeTargetScene(const TestView& view, const TextureSpec& target = plainWhite()) {
  Scene scene;
  scene.lighting.ambient = 1.0;
  SceneMaterial dark, white;
  dark.name = "dark";
  dark.texture.pattern = "plain";
  dark.texture.albedo = 0.1;
  white.name = "target";
  white.texture = target;
  const int m_dark = scene.addMaterial(dark), m_white = scene.addMaterial(white);
  const int room = scene.addObject("room");
  const Eigen::Vector3d c = view.T_w_c().translation();
  scene.addBox(c + Eigen::Vector3d(0, 0, -20), Eigen::Matrix3d::Identity(), {80, 80, 1}, m_dark,
               room);
  for (int s : {-1, 1}) {
    scene.addBox(c + Eigen::Vector3d(20.5 * s, 0, 0), Eigen::Matrix3d::Identity(), {1, 80, 80},
                 m_dark, room);
    scene.addBox(c + Eigen::Vector3d(0, 20.5 * s, 0), Eigen::Matrix3d::Identity(), {80, 1, 80},
                 m_dark, room);
  }
  scene.addBox(c + Eigen::Vector3d(0, 0, 20), Eigen::Matrix3d::Identity(), {80, 80, 1}, m_dark,
               room);
  const Eigen::Matrix3d R_w_c = view.T_w_c().linear();
  const double pixels[8][3] = {{90, 70, 2.0},   {376, 60, 3.0}, {660, 75, 2.5},  {70, 240, 4.0},
                               {680, 250, 3.5}, {95, 410, 2.2}, {380, 420, 5.0}, {655, 405, 2.8}};
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d ray =
        view.camera->backProject(Eigen::Vector2d(pixels[i][0], pixels[i][1])).normalized();
    const Eigen::Vector3d center = c + R_w_c * (ray * pixels[i][2]);
    // Facing the camera, turned by 25 degrees about a tilted axis and rolled.
    const Eigen::Vector3d to_camera = (c - center).normalized();
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(0.44, (R_w_c.col(0) + 0.5 * R_w_c.col(1)).normalized()) *
        Eigen::AngleAxisd(0.3 + 0.2 * i, to_camera).toRotationMatrix();
    const Eigen::Vector3d n = turn * to_camera;
    const Eigen::Vector3d u = n.unitOrthogonal();
    const Eigen::Vector3d v = n.cross(u);
    SceneQuad q;
    q.edge_u = u * 0.16 * pixels[i][2];
    q.edge_v = v * 0.11 * pixels[i][2];
    q.origin = center - 0.5 * q.edge_u - 0.5 * q.edge_v;
    q.material = m_white;
    q.object = scene.addObject("target" + std::to_string(i));
    q.two_sided = true;
    scene.addQuad(q);
  }
  scene.finalize();
  return scene;
}

AppearanceOptions cleanAppearance() {
  AppearanceOptions ao;
  ao.occlusion_rays = 0;
  ao.shadows = false;
  return ao;
}

cv::Mat1b renderClean(const Scene& scene, const TestView& view, int threads = 1) {
  const SceneAppearance appearance(scene, cleanAppearance());
  CameraSimulationOptions o;
  o.render.threads = threads;
  o.sensor.add_noise = false;
  o.sensor.optical_blur_sigma_px = 0;
  o.sensor.vignetting = 0;
  o.sensor.target_mean_dn = 0;
  o.sensor.exposure_dn = 250;
  const CameraSimulator sim(scene, appearance, *view.camera, view.config.camera.T_b_c, o);
  // A trajectory standing still at T_w_b.
  const Eigen::Quaterniond q(view.T_w_b.linear());
  const PoseSpline still(0.0, 1.0, Vector3dList(4, view.T_w_b.translation()), QuaternionList(4, q));
  return sim.render(still, 0.5, 0.5);
}

bool projectToImage(const TestView& view, const Eigen::Isometry3d& T_w_c, const Eigen::Vector3d& X,
                    Eigen::Vector2d* px, double margin) {
  return view.camera->project(T_w_c.inverse() * X, px) && view.camera->inImage(*px, margin);
}

// Where the intensity profile through p along the unit normal n crosses half way
// between the dark and bright levels, as an offset along n in pixels (1e9: none).
double edgeCrossing(const cv::Mat1f& img, const Eigen::Vector2d& p, const Eigen::Vector2d& n) {
  const double half = 0.5 * (25 + 225);
  std::vector<double> profile;
  for (int k = -32; k <= 32; ++k) {
    const Eigen::Vector2d x = p + n * (k / 8.0);
    cv::Mat1f patch;
    cv::getRectSubPix(img, cv::Size(1, 1), cv::Point2f(x.x(), x.y()), patch);
    profile.push_back(patch(0, 0));
  }
  const bool rising = profile.back() > profile.front();
  for (int k = 0; k + 1 < static_cast<int>(profile.size()); ++k) {
    const double a = profile[k] - half, b = profile[k + 1] - half;
    if ((rising && a <= 0 && b > 0) || (!rising && a >= 0 && b < 0))
      return (k + a / (a - b) - 32) / 8.0;
  }
  return 1e9;
}

// The half-height crossing (px, along the image normal) at fraction f of the 3D edge e, whose
// projection lands at *px; false when that part of the edge is outside the image.
bool crossingAcrossEdge(const TestView& view, const cv::Mat1f& img, const SceneEdge& e, double f,
                        Eigen::Vector2d* px, double* crossing) {
  Eigen::Vector2d q;
  if (!projectToImage(view, view.T_w_c(), e.a + (e.b - e.a) * f, px, 8) ||
      !projectToImage(view, view.T_w_c(), e.a + (e.b - e.a) * (f + 0.01), &q, 8))
    return false;
  const Eigen::Vector2d t = (q - *px).normalized();
  *crossing = edgeCrossing(img, *px, Eigen::Vector2d(-t.y(), t.x()));
  return true;
}

// The rendered corner where the two edges from `corner` towards `a` and `b` meet:
// each edge is located (half-height crossings) 4..20 px from the corner, fitted by
// a line, and the lines are intersected.
bool measureCornerFromEdges(const TestView& view, const cv::Mat1f& img,
                            const Eigen::Vector3d& corner, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, Eigen::Vector2d* out) {
  Eigen::Vector2d pc;
  if (!projectToImage(view, view.T_w_c(), corner, &pc, 25)) return false;
  Eigen::Vector3d lines[2];  // homogeneous image lines
  int li = 0;
  for (const Eigen::Vector3d* other : {&a, &b}) {
    Eigen::Vector2d po;
    view.camera->project(view.T_w_c().inverse() * *other, &po);
    const double length_px = (po - pc).norm();
    std::vector<Eigen::Vector2d> pts;
    for (double d = 4; d <= 20; d += 2) {
      const Eigen::Vector3d X = corner + (*other - corner) * (d / length_px);
      const Eigen::Vector3d Y = corner + (*other - corner) * ((d + 0.5) / length_px);
      Eigen::Vector2d p, q;
      view.camera->project(view.T_w_c().inverse() * X, &p);
      view.camera->project(view.T_w_c().inverse() * Y, &q);
      const Eigen::Vector2d t = (q - p).normalized();
      const Eigen::Vector2d n(-t.y(), t.x());
      const double c = edgeCrossing(img, p, n);
      if (std::abs(c) > 2) return false;
      pts.push_back(p + c * n);
    }
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : pts) mean += p / pts.size();
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const auto& p : pts) cov += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
    const Eigen::Vector2d normal = es.eigenvectors().col(0);  // smallest eigenvalue
    lines[li++] = Eigen::Vector3d(normal.x(), normal.y(), -normal.dot(mean));
  }
  const Eigen::Vector3d x = lines[0].cross(lines[1]);
  *out = x.head<2>() / x.z();
  return true;
}

// Sub-pixel corners found by cv::cornerSubPix from a guess 1.6 px off, paired with
// the projections of the scene's quad corners under T_w_c.
std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> findCorners(const Scene& scene,
                                                                     const TestView& view,
                                                                     const cv::Mat1b& image) {
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> pairs;
  for (const SceneQuad& q : scene.quads()) {
    if (!q.two_sided) continue;  // the room's faces
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector2d p;
      if (!projectToImage(view, view.T_w_c(), q.corner(k), &p, 12)) continue;
      std::vector<cv::Point2f> guess = {cv::Point2f(p.x() + 1.6f, p.y() - 1.3f)};
      cv::cornerSubPix(image, guess, cv::Size(4, 4), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 60, 1e-4));
      pairs.emplace_back(p, Eigen::Vector2d(guess[0].x, guess[0].y));
    }
  }
  return pairs;
}

}  // namespace

TEST(SimRender, SceneCornersLandOnRenderedCornersWithinHalfAPixel) {
  const TestView view;
  const Scene scene = makeTargetScene(view);
  const cv::Mat1b image = renderClean(scene, view);
  const auto pairs = findCorners(scene, view, image);
  ASSERT_GE(pairs.size(), 28u) << "most target corners should be in view";
  double max_err = 0, sum = 0;
  for (const auto& [projected, found] : pairs) {
    const double e = (projected - found).norm();
    EXPECT_LT(e, 0.5) << "corner projected at " << projected.transpose() << ", rendered at "
                      << found.transpose();
    max_err = std::max(max_err, e);
    sum += e;
  }
  std::cout << pairs.size() << " corners (cornerSubPix): mean error " << sum / pairs.size()
            << " px, max " << max_err << " px\n";

  // cornerSubPix has a bias of about 0.2 px on anti-aliased corners that are not
  // right angles; intersecting the two fitted edges locates corners more exactly.
  cv::Mat1f img;
  image.convertTo(img, CV_32F);
  int n = 0;
  double sum_fit = 0, max_fit = 0;
  for (const SceneQuad& q : scene.quads()) {
    if (!q.two_sided) continue;
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector2d measured, projected;
      if (!measureCornerFromEdges(view, img, q.corner(k), q.corner(k + 1), q.corner(k + 3),
                                  &measured))
        continue;
      view.camera->project(view.T_w_c().inverse() * q.corner(k), &projected);
      const double e = (measured - projected).norm();
      EXPECT_LT(e, 0.5) << "corner projected at " << projected.transpose();
      sum_fit += e;
      max_fit = std::max(max_fit, e);
      ++n;
    }
  }
  ASSERT_GE(n, 24);
  EXPECT_LT(sum_fit / n, 0.1);
  std::cout << n << " corners (edge fit): mean error " << sum_fit / n << " px, max " << max_fit
            << " px\n";
}

TEST(SimRender, AWrongExtrinsicOrLensWouldBeDetected) {
  // The same rendered corners, compared with projections through a camera that is
  // off by 0.3 degrees in T_b_c, or that ignores the lens distortion: the test above
  // must be sharp enough to see either.
  const TestView view;
  const Scene scene = makeTargetScene(view);
  const cv::Mat1b image = renderClean(scene, view);
  const auto pairs = findCorners(scene, view, image);
  ASSERT_GE(pairs.size(), 28u);

  Eigen::Isometry3d T_b_c_wrong = view.config.camera.T_b_c;
  T_b_c_wrong.linear() =
      T_b_c_wrong.linear() * Eigen::AngleAxisd(0.3 * M_PI / 180, Eigen::Vector3d::UnitY());
  CameraOptions pinhole = view.config.camera;
  pinhole.distortion_model = "none";
  pinhole.distortion_coefficients.clear();
  const auto undistorted = CameraModel::create(pinhole);
  double max_extrinsic = 0, max_lens = 0;
  for (const auto& [projected, found] : pairs) {
    // Recover the 3D corner from the projection, then reproject it wrongly.
    for (const SceneQuad& q : scene.quads())
      for (int k = 0; k < 4; ++k) {
        Eigen::Vector2d p;
        if (!view.camera->project(view.T_w_c().inverse() * q.corner(k), &p) ||
            (p - projected).norm() > 1e-9)
          continue;
        Eigen::Vector2d wrong;
        view.camera->project((view.T_w_b * T_b_c_wrong).inverse() * q.corner(k), &wrong);
        max_extrinsic = std::max(max_extrinsic, (wrong - found).norm());
        undistorted->project(view.T_w_c().inverse() * q.corner(k), &wrong);
        max_lens = std::max(max_lens, (wrong - found).norm());
      }
  }
  EXPECT_GT(max_extrinsic, 1.0);
  EXPECT_GT(max_lens, 10.0);
}

TEST(SimRender, SceneEdgesLandOnRenderedEdgesWithinHalfAPixel) {
  // Along every visible edge of the targets (the scene's edge list), the rendered
  // intensity step crosses half height within 0.5 px of the projected edge curve.
  const TestView view;
  const Scene scene = makeTargetScene(view);
  const cv::Mat1b image = renderClean(scene, view);
  cv::Mat1f img;
  image.convertTo(img, CV_32F);
  int samples = 0;
  double max_err = 0, sum = 0;
  for (const SceneEdge& e : scene.edges()) {
    if (scene.objectNames()[e.object].rfind("target", 0) != 0) continue;
    for (int s = 1; s < 10; ++s) {
      Eigen::Vector2d p;
      double crossing;
      if (!crossingAcrossEdge(view, img, e, 0.1 * s, &p, &crossing)) continue;
      ASSERT_LT(std::abs(crossing), 2.0) << "no edge near " << p.transpose();
      EXPECT_LT(std::abs(crossing), 0.5) << "edge at " << p.transpose();
      max_err = std::max(max_err, std::abs(crossing));
      sum += std::abs(crossing);
      ++samples;
    }
  }
  ASSERT_GT(samples, 200);
  EXPECT_LT(sum / samples, 0.15);
  std::cout << samples << " edge samples: mean offset " << sum / samples << " px, max " << max_err
            << " px\n";
}

TEST(SimRender, TextureEdgesLandOnRenderedEdgesWithinHalfAPixel) {
  // The same targets with a checkerboard that repeats every 0.512 m (tilted quads up to
  // 0.8 m wide, so most span a texture border), at random offsets: the texture edges
  // placed in 3D by sceneTextureEdges land on the rendered checker edges.
  const TestView view;
  TextureSpec checker;
  checker.pattern = "checker";
  checker.albedo = 0.5;
  checker.contrast = 0.4;  // 0.1 and 0.9, the levels edgeCrossing expects
  checker.texel_m = 0.002;
  checker.feature_m = 0.064;
  checker.texture_size = 256;
  const Scene scene = makeTargetScene(view, checker);
  const cv::Mat1b image = renderClean(scene, view);
  cv::Mat1f img;
  image.convertTo(img, CV_32F);
  TextureEdgeOptions teo;
  teo.min_length_m = 0.03;  // checker edges are one cell (0.064 m) long
  const std::vector<SceneEdge> edges =
      sceneTextureEdges(scene, SceneAppearance(scene, cleanAppearance()), teo);
  ASSERT_GT(edges.size(), 100u);
  // How far (m) a point of the target `object` lies inside its quad's border.
  auto insideBorder = [&](int object, const Eigen::Vector3d& X) {
    for (const SceneQuad& q : scene.quads()) {
      if (q.object != object) continue;
      const double a = (X - q.origin).dot(q.edge_u) / q.edge_u.norm();
      const double b = (X - q.origin).dot(q.edge_v) / q.edge_v.norm();
      return std::min({a, q.edge_u.norm() - a, b, q.edge_v.norm() - b});
    }
    return -1.0;
  };
  const double focal_px = 458;
  int samples = 0, edges_seen = 0;
  double sum = 0;
  for (const SceneEdge& e : edges) {
    if (scene.objectNames()[e.object].rfind("target", 0) != 0) continue;
    bool seen = false;
    // The middle of each cell edge, as the checker's corners are ambiguous; and not within
    // the crossing search's 4 px of the quad's border, where the background shows.
    for (int s = 3; s <= 7; ++s) {
      const Eigen::Vector3d X = e.a + (e.b - e.a) * (0.1 * s);
      const double depth = (X - view.T_w_c().translation()).norm();
      if (insideBorder(e.object, X) < 5 * depth / focal_px) continue;
      Eigen::Vector2d p;
      double crossing;
      if (!crossingAcrossEdge(view, img, e, 0.1 * s, &p, &crossing)) continue;
      ASSERT_LT(std::abs(crossing), 2.0) << "no edge near " << p.transpose();
      EXPECT_LT(std::abs(crossing), 0.5) << "edge at " << p.transpose();
      sum += std::abs(crossing);
      ++samples;
      seen = true;
    }
    edges_seen += seen;
  }
  ASSERT_GT(edges_seen, 100);
  EXPECT_LT(sum / samples, 0.15);
  std::cout << edges.size() << " texture edges, " << edges_seen << " in view, " << samples
            << " samples: mean offset " << sum / samples << " px\n";
}

TEST(SimRender, ThreadCountDoesNotChangeTheImage) {
  const TestView view;
  const Scene scene = makeTargetScene(view);
  const cv::Mat1b a = renderClean(scene, view, 1), b = renderClean(scene, view, 2);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}
