#include "alvio/io/text_table_reader.h"

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "alvio/common/error.h"

namespace alvio {

TextTableReader::TextTableReader(const std::string& path) : path_(path), in_(path) {
  if (!in_) throw Error("cannot open '" + path + "'");
}

std::string TextTableReader::where() const {
  return path_ + ":" + std::to_string(line_number_);
}

void TextTableReader::fail(const std::string& message) const {
  throw Error(where() + ": " + message);
}

bool TextTableReader::next(std::vector<std::string>* fields) {
  std::string line;
  while (std::getline(in_, line)) {
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    fields->clear();
    last_had_commas_ = line.find(',') != std::string::npos;
    if (last_had_commas_) {
      std::stringstream ss(line);
      std::string field;
      while (std::getline(ss, field, ',')) {
        const auto b = field.find_first_not_of(" \t");
        const auto e = field.find_last_not_of(" \t");
        fields->push_back(b == std::string::npos ? "" : field.substr(b, e - b + 1));
      }
      // "a,b," (VINS-Mono output) has a trailing comma: getline gives no empty field for it.
    } else {
      std::stringstream ss(line);
      std::string field;
      while (ss >> field) fields->push_back(field);
    }
    return true;
  }
  return false;
}

double TextTableReader::toDouble(const std::string& field, int column) const {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(field.c_str(), &end);
  if (field.empty() || end != field.c_str() + field.size() || errno == ERANGE || !std::isfinite(v))
    fail("column " + std::to_string(column + 1) + ": '" + field + "' is not a finite number");
  return v;
}

int64_t TextTableReader::toInt64(const std::string& field, int column) const {
  const auto bad = [&] {
    fail("column " + std::to_string(column + 1) + ": '" + field + "' is not an integer");
  };
  // Some files store ns stamps as "1403636580863555584.0000000000": parse the two parts
  // separately, since a double cannot hold 19 digits.
  const auto dot = field.find('.');
  const std::string whole = field.substr(0, dot);
  errno = 0;
  char* end = nullptr;
  long long v = std::strtoll(whole.c_str(), &end, 10);
  if (whole.empty() || end != whole.c_str() + whole.size() || errno == ERANGE) bad();
  if (dot != std::string::npos) {
    const std::string frac = field.substr(dot + 1);
    if (frac.find_first_not_of("0123456789") != std::string::npos) bad();
    // Round half away from zero; "-0.7" is negative although its whole part is 0.
    if (!frac.empty() && frac[0] >= '5') {
      const bool negative = whole[0] == '-';
      // Rounding the extreme values would overflow: undefined behaviour (UBSan, fuzz_euroc_csv).
      if (v == (negative ? LLONG_MIN : LLONG_MAX)) bad();
      v += negative ? -1 : 1;
    }
  }
  return v;
}

}  // namespace alvio
