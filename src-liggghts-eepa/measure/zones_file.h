// Reading a zones file inside LIGGGHTS (the format and parser: physics/zones.h).
#ifndef TSG_ZONES_FILE_H
#define TSG_ZONES_FILE_H

#include <string>
#include <vector>

#include "lammps.h"

#include "zones.h"

namespace tsg::measure {

// Rank 0 reads the file, every rank parses the same text, so a missing or bad file stops all ranks
// with the parser's message (file, line, reason), prefixed by `who` ("fix ID style"). The file is
// registered as an input of the run (run_files.h): no fix may write it.
std::vector<tsg::zones::Zone> read_zones(LAMMPS_NS::LAMMPS *lmp, const std::string &path, const std::string &who);

}  // namespace tsg::measure

#endif
