#include "alvio/io/euroc_dataset.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/io/text_table_reader.h"
#include "alvio/io/trajectory_io.h"

namespace fs = std::filesystem;

namespace alvio {

EurocDataset::EurocDataset(const std::string& root, TimeOrderPolicy policy) {
  if (!fs::is_directory(root)) throw Error("dataset folder '" + root + "' does not exist");
  fs::path mav0 = fs::path(root) / "mav0";
  if (!fs::is_directory(mav0)) {
    if (fs::is_directory(fs::path(root) / "cam0")) {
      mav0 = fs::path(root);
    } else {
      throw Error("'" + root + "' is not an EuRoC/ASL folder: no mav0/ or cam0/ inside");
    }
  }
  mav0_ = mav0.string();
  const fs::path cam_csv = mav0 / "cam0" / "data.csv";
  const fs::path imu_csv = mav0 / "imu0" / "data.csv";
  if (!fs::exists(cam_csv)) throw Error("EuRoC folder '" + root + "': missing " + cam_csv.string());
  if (!fs::exists(imu_csv)) throw Error("EuRoC folder '" + root + "': missing " + imu_csv.string());
  images_ = readEurocImageCsv(cam_csv.string(), (mav0 / "cam0" / "data").string(), policy);
  imu_ = readEurocImuCsv(imu_csv.string(), policy);
  const fs::path gt_csv = mav0 / "state_groundtruth_estimate0" / "data.csv";
  if (fs::exists(gt_csv)) ground_truth_ = readEurocGroundTruthCsv(gt_csv.string(), policy);
}

std::optional<CameraOptions> EurocDataset::cameraCalibration() const {
  const fs::path p = fs::path(mav0_) / "cam0" / "sensor.yaml";
  if (!fs::exists(p)) return std::nullopt;
  YamlReader yaml(p.string());
  return CameraOptions::load(yaml, "");
}

std::optional<ImuOptions> EurocDataset::imuCalibration() const {
  const fs::path p = fs::path(mav0_) / "imu0" / "sensor.yaml";
  if (!fs::exists(p)) return std::nullopt;
  YamlReader yaml(p.string());
  return ImuOptions::load(yaml, "");
}

std::vector<ImageRecord> readEurocImageCsv(const std::string& csv_path,
                                           const std::string& image_dir, TimeOrderPolicy policy) {
  TextTableReader reader(csv_path);
  std::vector<ImageRecord> out;
  std::vector<int> lines;
  std::vector<std::string> f;
  while (reader.next(&f)) {
    if (f.size() < 2)
      reader.fail("expected 'timestamp_ns,filename', got " + std::to_string(f.size()) +
                  " column(s)");
    ImageRecord r;
    r.t_ns = reader.toInt64(f[0], 0);
    r.path = (fs::path(image_dir) / f[1]).string();
    out.push_back(r);
    lines.push_back(reader.lineNumber());
  }
  enforceTimeOrder(&out, lines, csv_path, policy, [](const ImageRecord& r) { return r.t_ns; });
  return out;
}

std::vector<ImuSample> readEurocImuCsv(const std::string& csv_path, TimeOrderPolicy policy) {
  TextTableReader reader(csv_path);
  std::vector<ImuSample> out;
  std::vector<int> lines;
  std::vector<std::string> f;
  while (reader.next(&f)) {
    if (f.size() != 7)
      reader.fail("expected 7 columns (t_ns, w_xyz, a_xyz), got " + std::to_string(f.size()));
    ImuSample s;
    s.t_ns = reader.toInt64(f[0], 0);
    for (int i = 0; i < 3; ++i) s.gyr[i] = reader.toDouble(f[1 + i], 1 + i);
    for (int i = 0; i < 3; ++i) s.acc[i] = reader.toDouble(f[4 + i], 4 + i);
    out.push_back(s);
    lines.push_back(reader.lineNumber());
  }
  enforceTimeOrder(&out, lines, csv_path, policy, [](const ImuSample& s) { return s.t_ns; });
  return out;
}

GroundTruth readEurocGroundTruthCsv(const std::string& csv_path, TimeOrderPolicy policy) {
  TextTableReader reader(csv_path);
  GroundTruth out;
  std::vector<int> lines;
  std::vector<std::string> f;
  while (reader.next(&f)) {
    if (f.size() < 8)
      reader.fail("expected at least 8 columns (t_ns, p, q_wxyz), got " + std::to_string(f.size()));
    GroundTruthState s;
    s.t_ns = reader.toInt64(f[0], 0);
    for (int i = 0; i < 3; ++i) s.p[i] = reader.toDouble(f[1 + i], 1 + i);
    s.q = Eigen::Quaterniond(reader.toDouble(f[4], 4), reader.toDouble(f[5], 5),
                             reader.toDouble(f[6], 6), reader.toDouble(f[7], 7));
    if (std::abs(s.q.norm() - 1.0) > 1e-2) reader.fail("quaternion is not unit length");
    s.q.normalize();
    if (f.size() >= 17) {
      for (int i = 0; i < 3; ++i) s.v[i] = reader.toDouble(f[8 + i], 8 + i);
      for (int i = 0; i < 3; ++i) s.bg[i] = reader.toDouble(f[11 + i], 11 + i);
      for (int i = 0; i < 3; ++i) s.ba[i] = reader.toDouble(f[14 + i], 14 + i);
    }
    out.push_back(s);
    lines.push_back(reader.lineNumber());
  }
  enforceTimeOrder(&out, lines, csv_path, policy, [](const GroundTruthState& s) { return s.t_ns; });
  return out;
}

void writeEurocImageCsv(const std::string& csv_path, const std::vector<int64_t>& stamps_ns) {
  std::ostringstream os;
  os << "#timestamp [ns],filename\n";
  for (const auto t : stamps_ns) os << t << "," << t << ".png\n";
  writeFileAtomically(csv_path, os.str());
}

void writeEurocImuCsv(const std::string& csv_path, const std::vector<ImuSample>& imu) {
  std::string text =
      "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
      "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  char buf[256];
  for (const auto& s : imu) {
    std::snprintf(buf, sizeof(buf), "%lld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                  static_cast<long long>(s.t_ns), s.gyr.x(), s.gyr.y(), s.gyr.z(), s.acc.x(),
                  s.acc.y(), s.acc.z());
    text += buf;
  }
  writeFileAtomically(csv_path, text);
}

void writeEurocGroundTruthCsv(const std::string& csv_path, const GroundTruth& gt) {
  std::string text =
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
      "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
      "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
      "b_a_RS_S_z [m s^-2]\n";
  char buf[512];
  for (const auto& s : gt) {
    std::snprintf(buf, sizeof(buf),
                  "%lld,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9g,%.9g,%.9g,%.9g,%.9g,"
                  "%.9g\n",
                  static_cast<long long>(s.t_ns), s.p.x(), s.p.y(), s.p.z(), s.q.w(), s.q.x(),
                  s.q.y(), s.q.z(), s.v.x(), s.v.y(), s.v.z(), s.bg.x(), s.bg.y(), s.bg.z(),
                  s.ba.x(), s.ba.y(), s.ba.z());
    text += buf;
  }
  writeFileAtomically(csv_path, text);
}

namespace {
std::string joinNumbers(const std::vector<double>& v) {
  std::ostringstream os;
  os.precision(12);
  for (std::size_t i = 0; i < v.size(); ++i) os << (i ? ", " : "") << v[i];
  return os.str();
}
std::string matrixYaml(const Eigen::Matrix4d& m) {
  std::ostringstream os;
  os.precision(15);
  os << "  cols: 4\n  rows: 4\n  data: [";
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      os << m(r, c) << (r == 3 && c == 3 ? "]\n" : (c == 3 ? ",\n         " : ", "));
  return os.str();
}
}  // namespace

void writeEurocCameraYaml(const std::string& path, const CameraOptions& c) {
  std::ostringstream os;
  os << "%YAML:1.0\n# Written by alvio.\nsensor_type: camera\ncomment: alvio cam0\n\n"
     << "T_BS:\n"
     << matrixYaml(c.T_b_c.matrix()) << "\nrate_hz: " << c.rate_hz << "\n"
     << "resolution: [" << c.width << ", " << c.height << "]\n"
     << "camera_model: " << c.camera_model << "\n"
     << "intrinsics: [" << joinNumbers(c.intrinsics) << "] #fu, fv, cu, cv\n"
     << "distortion_model: " << c.distortion_model << "\n"
     << "distortion_coefficients: [" << joinNumbers(c.distortion_coefficients) << "]\n";
  writeFileAtomically(path, os.str());
}

void writeEurocImuYaml(const std::string& path, const ImuOptions& imu) {
  std::ostringstream os;
  os.precision(10);
  os << "%YAML:1.0\n# Written by alvio.\nsensor_type: imu\ncomment: alvio imu0\n\n"
     << "T_BS:\n"
     << matrixYaml(Eigen::Matrix4d::Identity()) << "rate_hz: " << imu.rate_hz << "\n\n"
     << "gyroscope_noise_density: " << imu.gyroscope_noise_density << "\n"
     << "gyroscope_random_walk: " << imu.gyroscope_random_walk << "\n"
     << "accelerometer_noise_density: " << imu.accelerometer_noise_density << "\n"
     << "accelerometer_random_walk: " << imu.accelerometer_random_walk << "\n";
  writeFileAtomically(path, os.str());
}

}  // namespace alvio
