// The files of a run that must not be confused: its log, the files it reads (zones files, meshes)
// and the files our fixes write (residence records, mass-flow sensors). One registry per process,
// keyed by canonical path (realpath of the folder + file name), so that "r.txt", "./r.txt" and a
// symlinked folder name the same file. Checked when each reader or writer is created: an output
// equal to an input, to another fix's output or to the log would destroy data silently.
//
// Dependency-free (POSIX realpath only): used by our fixes and by the patched upstream mesh reader
// (input_mesh_tri.cpp) and error handler (error.cpp, lammps.cpp, input.cpp).
#ifndef TSG_RUN_FILES_H
#define TSG_RUN_FILES_H

#include <climits>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace tsg::run_files {

// realpath of the folder + the file name (the file itself need not exist yet); the path as given
// when its folder does not exist (opening it fails later with its own message).
inline std::string canonical(const std::string &path)
{
  const std::string::size_type slash = path.rfind('/');
  const std::string folder = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  char resolved[PATH_MAX];
  if (!realpath(folder.c_str(), resolved)) return path;
  std::string full = resolved;
  if (full.back() != '/') full += '/';
  full += name;
  if (realpath(full.c_str(), resolved)) return resolved;  // an existing file: follow its symlinks too
  return full;
}

struct Entry {
  std::string canonical;
  std::string path;   // as the user wrote it
  std::string owner;  // e.g. "fix rt residence/time"
  std::string role;   // e.g. "records file"
  bool output;
};

inline std::vector<Entry> &registry()
{
  static std::vector<Entry> entries;
  return entries;
}

inline std::string &log_name()
{
  static std::string name;
  return name;
}

// The log file of this run ("" for none), known on every rank (error.cpp appends to it the error of
// a rank that does not write the log).
inline void set_log(const std::string &path) { log_name() = path; }
inline const std::string &log_path() { return log_name(); }

// Opens the log on rank 0: truncated unless `append`, then written in append mode and line-buffered,
// so that every line written before an abort is in the file, and a line another rank appends is never
// overwritten. nullptr when it cannot be opened.
inline FILE *open_log(const char *path, bool append)
{
  if (!append) {
    FILE *fp = std::fopen(path, "w");
    if (!fp) return nullptr;
    std::fclose(fp);
  }
  FILE *fp = std::fopen(path, "a");
  if (fp) std::setvbuf(fp, nullptr, _IOLBF, BUFSIZ);
  return fp;
}

// Appends an error line to the log (for a rank that does not write the log: MPI_Abort follows).
inline void append_to_log(const std::string &line)
{
  if (log_name().empty()) return;
  if (FILE *fp = std::fopen(log_name().c_str(), "a")) {
    std::fputs(line.c_str(), fp);
    std::fclose(fp);
  }
}

namespace detail {
inline std::string describe(const Entry &e)
{
  return "the " + e.role + " of " + e.owner + " '" + e.path + "'" +
         (e.output ? " (written by this run)" : " (read by this run)");
}
}  // namespace detail

// Registers `path` as the `role` written by `owner`; returns "" or why it cannot be: the file is the
// log, an input of the run or another output.
inline std::string claim_output(const std::string &path, const std::string &owner, const std::string &role)
{
  const std::string key = canonical(path);
  const std::string self = "the " + role + " of " + owner + " '" + path + "'";
  if (!log_name().empty() && canonical(log_name()) == key)
    return self + " is the log file of this run; choose another file name";
  for (const Entry &e : registry())
    if (e.canonical == key)
      return self + " is the same file as " + detail::describe(e) +
             "; writing it would destroy that data: choose another file name";
  registry().push_back({key, path, owner, role, true});
  return "";
}

// Registers `path` as the `role` read by `owner`; returns "" or why it cannot be: it is an output.
inline std::string note_input(const std::string &path, const std::string &owner, const std::string &role)
{
  const std::string key = canonical(path);
  for (const Entry &e : registry())
    if (e.canonical == key && e.output)
      return "the " + role + " of " + owner + " '" + path + "' is the same file as " + detail::describe(e) +
             "; it would be overwritten while it is in use: choose another file name";
  registry().push_back({key, path, owner, role, false});
  return "";
}

// Forgets every file registered by `owner` (a fix or compute that is deleted or replaced).
inline void release(const std::string &owner)
{
  auto &entries = registry();
  for (auto it = entries.begin(); it != entries.end();) {
    if (it->owner == owner)
      it = entries.erase(it);
    else
      ++it;
  }
}

}  // namespace tsg::run_files

#endif
