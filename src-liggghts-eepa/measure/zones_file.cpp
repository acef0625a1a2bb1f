// Reading a zones file inside LIGGGHTS: see zones_file.h.
#include "zones_file.h"

#include <cstdio>
#include <stdexcept>

#include "errors.h"
#include "output_files.h"

namespace tsg::measure {

std::vector<tsg::zones::Zone> read_zones(LAMMPS_NS::LAMMPS *lmp, const std::string &path, const std::string &who)
{
  note_input(lmp, who, "zones file", path);
  std::string text;
  long size = 0;
  if (lmp->comm->me == 0) {
    if (FILE *fp = std::fopen(path.c_str(), "rb")) {
      char buffer[4096];
      std::size_t n;
      while ((n = std::fread(buffer, 1, sizeof buffer, fp)) > 0) text.append(buffer, n);
      std::fclose(fp);
      size = static_cast<long>(text.size());
    } else {
      size = -1;
    }
  }
  MPI_Bcast(&size, 1, MPI_LONG, 0, lmp->world);
  if (size < 0) fail(lmp, who, "cannot open zones file '" + path + "' (missing or not readable)");
  text.resize(static_cast<std::size_t>(size));
  if (size > 0) MPI_Bcast(&text[0], static_cast<int>(size), MPI_CHAR, 0, lmp->world);
  try {
    return tsg::zones::parse_zones_text(text, "zones file '" + path + "'");
  } catch (const std::invalid_argument &e) {
    fail(lmp, who, e.what());
  }
  return {};
}

}  // namespace tsg::measure
