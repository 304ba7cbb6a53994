#pragma once
// Line-by-line reader for the CSV/space-separated text files of datasets and
// trajectories. Skips blank and '#' lines and reports errors as "file:line: ...".

#include <fstream>
#include <string>
#include <vector>

namespace alvio {

class TextTableReader {
 public:
  /// Throws alvio::Error if the file cannot be opened.
  explicit TextTableReader(const std::string& path);

  /// Next data row split into fields (',' or whitespace separated; a trailing
  /// comma gives no empty field). False at end of file.
  bool next(std::vector<std::string>* fields);

  int lineNumber() const { return line_number_; }
  const std::string& path() const { return path_; }
  /// "file:line" of the row returned last.
  std::string where() const;
  /// Whether the last row was comma separated.
  bool lastRowHadCommas() const { return last_had_commas_; }

  /// Parse helpers that throw alvio::Error naming file, line and column.
  double toDouble(const std::string& field, int column) const;
  int64_t toInt64(const std::string& field, int column) const;
  [[noreturn]] void fail(const std::string& message) const;

 private:
  std::string path_;
  std::ifstream in_;
  int line_number_ = 0;
  bool last_had_commas_ = false;
};

}  // namespace alvio
