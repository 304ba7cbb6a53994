#include "alvio/pipeline/analysis_writer.h"

#include <filesystem>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/pipeline/vio_pipeline.h"

namespace alvio {

namespace {
void open(std::ofstream* f, const std::string& path, const char* header) {
  f->open(path, std::ios::trunc);
  if (!*f) throw Error("cannot write '" + path + "'");
  *f << header << "\n";
  *f << std::fixed;
  f->precision(6);
}
}  // namespace

AnalysisWriter::AnalysisWriter(const std::string& dir, int image_width, int image_height)
    : dir_(dir) {
  std::filesystem::create_directories(dir);
  // The fitted surfaces are normalised by the image size, so `alvio analyze` must know it.
  std::ofstream size_file(dir + "/image_size.yaml", std::ios::trunc);
  size_file << "width: " << image_width << "\nheight: " << image_height << "\n";
  if (!size_file) throw Error("cannot write '" + dir + "/image_size.yaml'");
  open(&points_, dir + "/points.csv", "window_t,id,x_px,y_px,tracked_frames");
  open(&lines_, dir + "/lines.csv", "window_t,id,x_px,y_px,tracked_frames");
  open(&windows_csv_, dir + "/windows.csv",
       "window_t,frames,mean_intensity,motion_m,points,lines,mean_point_track,mean_line_track");
}

void AnalysisWriter::onFrame(const FrameView& frame) {
  for (const WindowTrackRecord& r : frame.output.window_records) {
    double point_sum = 0, line_sum = 0;
    for (const auto& f : r.points) {
      points_ << r.t << "," << f.id << "," << f.px.x() << "," << f.px.y() << "," << f.tracked_frames
              << "\n";
      point_sum += f.tracked_frames;
    }
    for (const auto& f : r.lines) {
      lines_ << r.t << "," << f.id << "," << f.px.x() << "," << f.px.y() << "," << f.tracked_frames
             << "\n";
      line_sum += f.tracked_frames;
    }
    windows_csv_ << r.t << "," << r.frames << "," << r.mean_intensity << "," << r.motion_m << ","
                 << r.points.size() << "," << r.lines.size() << ","
                 << (r.points.empty() ? 0.0 : point_sum / r.points.size()) << ","
                 << (r.lines.empty() ? 0.0 : line_sum / r.lines.size()) << "\n";
    ++windows_;
  }
}

void AnalysisWriter::onFinish(const RunResult&) {
  points_.flush();
  lines_.flush();
  windows_csv_.flush();
  if (!points_ || !lines_ || !windows_csv_)
    throw Error("writing the analysis files in '" + dir_ + "' failed");
  logInfo("sensitivity-analysis records of ", windows_, " windows written to ", dir_);
}

}  // namespace alvio
