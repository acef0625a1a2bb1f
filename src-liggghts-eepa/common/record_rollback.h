// Records written after the restart file a run continues from. A job killed at its time limit has
// written records past its last restart file; the continued run writes them again from that file's
// state. Before it appends, the records whose time lies after the restart are dropped, so each is in
// the file once (a continued run equals one run in one piece).
//
// Dependency-free: the text of an output file in, the kept text out.
#ifndef TSG_RECORD_ROLLBACK_H
#define TSG_RECORD_ROLLBACK_H

#include <cstddef>
#include <istream>
#include <ostream>
#include <string>

#include "numbers.h"

namespace tsg {

// Copies `in` to `out` without the data lines whose `time_column` (1-based, whitespace-separated)
// holds a time above `limit`; comment lines ('#') and lines without that column are kept. Returns
// the number of lines dropped.
inline std::size_t keep_records_until(std::istream &in, std::ostream &out, int time_column, double limit)
{
  std::size_t dropped = 0;
  for (std::string line; std::getline(in, line);) {
    bool keep = true;
    if (!line.empty() && line[0] != '#') {
      std::string::size_type start = 0;
      for (int column = 1; start != std::string::npos; ++column) {
        start = line.find_first_not_of(" \t", start);
        if (start == std::string::npos) break;
        const std::string::size_type end = line.find_first_of(" \t", start);
        if (column == time_column) {
          const std::string word = line.substr(start, end == std::string::npos ? std::string::npos : end - start);
          double time = 0.0;
          keep = !(scan_real(word.c_str(), time) && time > limit);
          break;
        }
        start = end;
      }
    }
    if (keep) {
      out << line << '\n';
    } else {
      ++dropped;
    }
  }
  return dropped;
}

}  // namespace tsg

#endif
