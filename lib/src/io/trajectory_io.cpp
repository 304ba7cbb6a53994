#include "alvio/io/trajectory_io.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/io/text_table_reader.h"

namespace alvio {

TrajectoryFormat parseTrajectoryFormat(const std::string& name) {
  if (name == "auto") return TrajectoryFormat::kAuto;
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "euroc") return TrajectoryFormat::kEuroc;
  if (name == "vins" || name == "vins-mono") return TrajectoryFormat::kVinsMono;
  throw Error("unknown trajectory format '" + name + "' (expected auto, tum, euroc or vins)");
}

const char* trajectoryFormatName(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kAuto:
      return "auto";
    case TrajectoryFormat::kTum:
      return "tum";
    case TrajectoryFormat::kEuroc:
      return "euroc";
    case TrajectoryFormat::kVinsMono:
      return "vins";
  }
  return "?";
}

TrajectoryFormat detectTrajectoryFormat(const std::string& path) {
  TextTableReader reader(path);
  std::vector<std::string> fields;
  if (!reader.next(&fields)) throw Error(path + ": no data rows");
  if (reader.lastRowHadCommas()) {
    if (fields.size() < 8)
      reader.fail("a CSV trajectory needs at least 8 columns (t_ns,px,py,pz,qw,qx,qy,qz), got " +
                  std::to_string(fields.size()));
    // VINS-Mono rows end with a comma; EuRoC's do not.
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
      while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
      if (line.empty() || line[0] == '#') continue;
      return line.back() == ',' ? TrajectoryFormat::kVinsMono : TrajectoryFormat::kEuroc;
    }
  }
  if (fields.size() == 8) return TrajectoryFormat::kTum;
  reader.fail("cannot tell the trajectory format: " + std::to_string(fields.size()) +
              " whitespace-separated columns (TUM has 8); pass the format explicitly");
}

Trajectory readTrajectory(const std::string& path, TrajectoryFormat format,
                          TimeOrderPolicy policy) {
  if (format == TrajectoryFormat::kAuto) format = detectTrajectoryFormat(path);
  TextTableReader reader(path);
  Trajectory out;
  std::vector<int> lines;
  std::vector<std::string> f;
  const bool tum = format == TrajectoryFormat::kTum;
  while (reader.next(&f)) {
    if (tum ? f.size() != 8 : f.size() < 8)
      reader.fail(std::string("expected ") + (tum ? "8" : "at least 8") + " columns for " +
                  trajectoryFormatName(format) + ", got " + std::to_string(f.size()));
    StampedPose pose;
    double q[4];
    if (tum) {
      pose.t = reader.toDouble(f[0], 0);
      // Stamps are compared as int64 ns: beyond that range (year 2262) they would wrap
      // and pass the time-order check out of order (found by fuzz_tum_trajectory).
      if (!(std::abs(pose.t) < 9.2e9))
        reader.fail("column 1: time " + f[0] + " s is out of range (|t| < 9.2e9 s)");
      for (int i = 0; i < 3; ++i) pose.p[i] = reader.toDouble(f[1 + i], 1 + i);
      for (int i = 0; i < 4; ++i) q[i] = reader.toDouble(f[4 + i], 4 + i);  // x y z w
      pose.q = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
    } else {
      pose.t = nsToSec(reader.toInt64(f[0], 0));
      for (int i = 0; i < 3; ++i) pose.p[i] = reader.toDouble(f[1 + i], 1 + i);
      for (int i = 0; i < 4; ++i) q[i] = reader.toDouble(f[4 + i], 4 + i);  // w x y z
      pose.q = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    }
    const double norm = pose.q.norm();
    if (std::abs(norm - 1.0) > 1e-2)
      reader.fail("quaternion norm is " + std::to_string(norm) + ", not 1 (wrong column order?)");
    pose.q.normalize();
    out.push_back(pose);
    lines.push_back(reader.lineNumber());
  }
  if (out.empty()) throw Error(path + ": no poses");
  enforceTimeOrder(&out, lines, path, policy, [](const StampedPose& p) { return secToNs(p.t); });
  return out;
}

void writeFileAtomically(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error("cannot write '" + tmp + "'");
    out << content;
    out.flush();
    if (!out) throw Error("write to '" + tmp + "' failed (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw Error("cannot rename '" + tmp + "' to '" + path + "': " + ec.message());
}

void writeTumTrajectory(const std::string& path, const Trajectory& trajectory) {
  std::string text = "# timestamp tx ty tz qx qy qz qw\n";
  char buf[256];
  for (const auto& s : trajectory) {
    std::snprintf(buf, sizeof(buf), "%.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", s.t, s.p.x(),
                  s.p.y(), s.p.z(), s.q.x(), s.q.y(), s.q.z(), s.q.w());
    text += buf;
  }
  writeFileAtomically(path, text);
}

}  // namespace alvio
