// The output files of our styles: registered against the run's other files (run_files.h), opened on
// rank 0 with a header that an appended file must share, and rolled back to the restart a continued
// run starts from (record_rollback.h).
#ifndef TSG_OUTPUT_FILES_H
#define TSG_OUTPUT_FILES_H

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "comm.h"
#include "error.h"
#include "lammps.h"

#include "arguments.h"
#include "errors.h"
#include "numbers.h"
#include "record_rollback.h"
#include "run_files.h"

namespace tsg {

// Registers a file the style writes / reads (run_files.h); an error when it is already in use.
inline void claim_output(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &role,
                         const std::string &path)
{
  const std::string problem = tsg::run_files::claim_output(path, who, role);
  if (!problem.empty()) fail(lmp, who, problem);
}

inline void note_input(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &role, const std::string &path)
{
  const std::string problem = tsg::run_files::note_input(path, who, role);
  if (!problem.empty()) fail(lmp, who, problem);
}

// How an output file is opened when the first run starts.
enum class Append {
  automatic,  // not given: append when the fix continues from a restart file, else start a new file
  yes,        // always append (the header of a non-empty file must match)
  no          // start a new file; refused when continuing from a restart and the file holds data
};

inline Append parse_append(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const char *value)
{
  return parse_yes_no(lmp, who, "append", value) ? Append::yes : Append::no;
}

namespace detail {

inline std::vector<std::string> header_lines(const std::string &text, const std::vector<std::string> &free_prefixes)
{
  std::vector<std::string> lines;
  std::string::size_type start = 0;
  while (start < text.size() && text[start] == '#') {
    std::string::size_type end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    bool free = false;
    for (const std::string &prefix : free_prefixes) free = free || line.compare(0, prefix.size(), prefix) == 0;
    if (!free) lines.push_back(line);
    start = end + 1;
  }
  return lines;
}

}  // namespace detail

// Where a continued run's records start: a fix continuing from a restart file drops the records of
// its file whose time (column `time_column`, 1-based) lies after `restart_time`, which the run that
// wrote the restart file went on to write before it ended (a job killed at its time limit); the
// continued run writes them again.
struct Rollback {
  int time_column;
  double restart_time;
};

// Opens an output file on rank 0 (nullptr on the other ranks) and writes `header` into a new or
// empty file. Appending to a file that holds data requires its header to equal `header`, except lines
// starting with one of `free_prefixes` (names that may change without changing what the columns
// mean): records of two set-ups never mix in one file. When continuing, the records after the
// restart are dropped first (Rollback) and their number is reported. Errors on every rank.
inline FILE *open_output(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &role,
                         const std::string &path, const std::string &header, Append mode, bool continuing,
                         const std::vector<std::string> &free_prefixes, const Rollback &rollback)
{
  const bool append = mode == Append::yes || (mode == Append::automatic && continuing);
  std::string problem;
  FILE *fp = nullptr;
  if (lmp->comm->me == 0) {
    // the header lines (leading '#' lines) of the file as it is, and its size; not the whole file
    std::string old;
    long size = 0;
    std::ifstream in(path, std::ios::binary);
    if (in) {
      for (std::string line; std::getline(in, line) && !line.empty() && line[0] == '#';) old += line + "\n";
      in.clear();
      in.seekg(0, std::ios::end);
      size = static_cast<long>(in.tellg());
    }
    if (size > 0 && mode == Append::no && continuing) {
      problem = "'append no' would overwrite the " + role + " '" + path + "' (" + std::to_string(size) +
                " bytes) that the run which wrote the restart file may have filled; continue it with 'append yes' "
                "(the default after read_restart) or give another file name";
    } else if (size > 0 && append) {
      const auto had = detail::header_lines(old, free_prefixes), want = detail::header_lines(header, free_prefixes);
      if (had != want) {
        std::size_t k = 0;
        while (k < had.size() && k < want.size() && had[k] == want[k]) ++k;
        problem = "cannot append to the " + role + " '" + path +
                  "': it was written for another set-up (its header has '" +
                  (k < had.size() ? had[k] : std::string("(no line)")) + "' where this fix writes '" +
                  (k < want.size() ? want[k] : std::string("(no line)")) +
                  "'); append only to a file of the same set-up, or give another file name";
      }
    }
    if (problem.empty() && size > 0 && append && continuing) {
      std::ifstream text(path, std::ios::binary);
      std::ostringstream rest;
      const std::size_t dropped = keep_records_until(text, rest, rollback.time_column, rollback.restart_time);
      text.close();
      if (dropped > 0) {
        std::ofstream rewritten(path + ".rollback", std::ios::binary | std::ios::trunc);
        rewritten << rest.str();
        rewritten.close();
        if (!rewritten || std::rename((path + ".rollback").c_str(), path.c_str()) != 0) {
          problem =
              "cannot drop the records after the restart from the " + role + " '" + path + "': " + std::strerror(errno);
        } else {
          const std::string note = who + ": dropped " + std::to_string(dropped) +
                                   " records after t = " + number(rollback.restart_time) + " s from the " + role +
                                   " '" + path +
                                   "' (written after the restart file by the run that wrote it; this run "
                                   "writes them again)";
          lmp->error->message(FLERR, note.c_str());
        }
      }
    }
    if (problem.empty()) {
      fp = std::fopen(path.c_str(), append ? "a" : "w");
      if (!fp) {
        problem = "cannot open the " + role + " '" + path + "' for writing: " + std::strerror(errno);
      } else if (!append || size == 0) {
        std::fputs(header.c_str(), fp);
        std::fflush(fp);
      }
    }
  }
  problem = broadcast_text(lmp->world, problem, 0);
  if (!problem.empty()) {
    if (fp) std::fclose(fp);
    fail(lmp, who, problem);
  }
  return fp;
}

}  // namespace tsg

#endif
