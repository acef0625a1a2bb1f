// Unit tests of the registry of a run's files (src-liggghts-eepa/common/run_files.h): one file under any
// spelling, outputs that collide with inputs, other outputs or the log; the log that another rank
// appends to.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "run_files.h"

namespace {

namespace rf = tsg::run_files;

class RunFiles : public ::testing::Test {
protected:
  void SetUp() override
  {
    char pattern[] = "/tmp/tsg_run_files_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
    rf::registry().clear();
    rf::set_log("");
  }
  void TearDown() override
  {
    rf::registry().clear();
    rf::set_log("");
    std::system(("rm -rf " + dir_).c_str());
  }
  std::string dir_;
};

std::string read(const std::string &path)
{
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST_F(RunFiles, OneFileUnderAnySpelling)
{
  ASSERT_EQ(mkdir((dir_ + "/sub").c_str(), 0700), 0);
  ASSERT_EQ(symlink((dir_ + "/sub").c_str(), (dir_ + "/link").c_str()), 0);
  const std::string plain = rf::canonical(dir_ + "/sub/r.txt");  // need not exist
  EXPECT_EQ(rf::canonical(dir_ + "/sub/../sub/./r.txt"), plain);
  EXPECT_EQ(rf::canonical(dir_ + "/link/r.txt"), plain);
  EXPECT_NE(rf::canonical(dir_ + "/sub/s.txt"), plain);
}

TEST_F(RunFiles, AnOutputMayNotBeAnInputOrAnotherOutput)
{
  const std::string zones = dir_ + "/zones.txt", records = dir_ + "/r.txt";
  EXPECT_EQ(rf::note_input(zones, "fix rt residence/time", "zones file"), "");
  EXPECT_EQ(rf::note_input(zones, "compute es element/stats", "zones file"), "");  // two readers: fine
  const std::string same = rf::claim_output(dir_ + "/./zones.txt", "fix rt residence/time", "records file");
  EXPECT_NE(same.find("is the same file as the zones file of fix rt residence/time"), std::string::npos) << same;
  EXPECT_EQ(rf::claim_output(records, "fix rt residence/time", "records file"), "");
  const std::string twice = rf::claim_output(records, "fix mf massflow/planes", "mass-flow file");
  EXPECT_NE(twice.find("the mass-flow file of fix mf massflow/planes"), std::string::npos) << twice;
  EXPECT_NE(twice.find("the records file of fix rt residence/time"), std::string::npos) << twice;
  const std::string read_back = rf::note_input(records, "compute es element/stats", "zones file");
  EXPECT_NE(read_back.find("(written by this run)"), std::string::npos) << read_back;
}

TEST_F(RunFiles, ReleasingAFixFreesItsFiles)
{
  const std::string records = dir_ + "/r.txt";
  EXPECT_EQ(rf::claim_output(records, "fix rt residence/time", "records file"), "");
  rf::release("fix rt residence/time");  // unfix, or the fix replaced by one of the same ID
  EXPECT_EQ(rf::claim_output(records, "fix rt residence/time", "records file"), "");
}

TEST_F(RunFiles, TheLogIsNoOutputAndTakesTheLinesOfAnotherRank)
{
  const std::string log = dir_ + "/log.lammps";
  rf::set_log(log);
  EXPECT_NE(rf::claim_output(dir_ + "/log.lammps", "fix rt residence/time", "records file").find("is the log file"),
            std::string::npos);
  FILE *rank0 = rf::open_log(log.c_str(), false);
  ASSERT_NE(rank0, nullptr);
  std::fputs("Step Atoms\n0 2\n", rank0);  // line-buffered: in the file at once
  rf::append_to_log("ERROR on proc 1: boom\n");
  std::fputs("10 2\n", rank0);  // append mode: after the other rank's line, not over it
  std::fclose(rank0);
  EXPECT_EQ(read(log), "Step Atoms\n0 2\nERROR on proc 1: boom\n10 2\n");
  FILE *again = rf::open_log(log.c_str(), false);  // a new log (the `log` command) starts empty
  std::fclose(again);
  EXPECT_EQ(read(log), "");
}

}  // namespace
