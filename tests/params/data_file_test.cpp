// SPDX-License-Identifier: GPL-2.0-or-later
// The checks every user-supplied YAML file passes before it is parsed (params/
// data_file.hpp): overlays, profiles and fault tables are a few KB of text; a wrong path
// gets a one-line reason, and a huge file is refused before it is read, let alone parsed
// (a 126 MB profile used to take 886 MB of memory).
#include "params/data_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "params/param_db.hpp"

namespace fs = std::filesystem;
using namespace i20::params;

namespace {

class DataFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("i20-data-file-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& content) {
    const auto p = dir_ / name;
    std::ofstream(p, std::ios::binary) << content;
    return p;
  }
  // A sparse file: its size is on record, no byte of it is on disk.
  fs::path sized(const std::string& name, std::uintmax_t bytes) {
    const auto p = write(name, "");
    fs::resize_file(p, bytes);
    return p;
  }
  fs::path dir_;
};

TEST_F(DataFile, ReadsATextFile) {
  const auto file = read_data_file(write("ok.yaml", "schema: 1\r\n\tparameters: []\n"), "profile");
  EXPECT_EQ(file.problem, "");
  EXPECT_EQ(file.text, "schema: 1\r\n\tparameters: []\n");
}

TEST_F(DataFile, RefusesMissingFilesAndDirectories) {
  EXPECT_EQ(read_data_file(dir_ / "nope.yaml", "profile").problem,
            "cannot open the profile (does it exist and is it readable?)");
  EXPECT_EQ(read_data_file(dir_, "profile").problem, "is a directory, not a profile");
}

TEST_F(DataFile, RefusesFilesAboveTheLimitBeforeReadingThem) {
  EXPECT_EQ(read_data_file(write("exact.yaml", std::string(kMaxDataFileBytes, '#')), "profile").problem, "")
      << "exactly at the limit is fine";
  const std::string too_large =
      "the profile is larger than 1048576 bytes, the limit for it (a real one is a few KB)";
  EXPECT_EQ(read_data_file(sized("over.yaml", kMaxDataFileBytes + 1), "profile").problem, too_large);
  // 4 GiB: only the size is looked at, so this takes no time and no memory.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(read_data_file(sized("huge.yaml", std::uintmax_t{4} << 30), "profile").problem, too_large);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
}

TEST_F(DataFile, ReadsDevicesAndPipesOnlyUpToTheLimit) {
  if (!fs::exists("/dev/zero")) GTEST_SKIP() << "no /dev/zero";
  EXPECT_EQ(read_data_file("/dev/zero", "fault table").problem,
            "the fault table is larger than 1048576 bytes, the limit for it (a real one is a few KB)");
}

TEST_F(DataFile, RefusesBinaryFilesNamingTheFirstControlByte) {
  EXPECT_EQ(read_data_file(write("bin.yaml", std::string("schema: 1\n\0\x7F", 12)), "parameter file").problem,
            "the parameter file holds the control byte 0x00 at offset 10: it is not a YAML text file");
  EXPECT_EQ(read_data_file(write("esc.yaml", "name: \x1B[31m"), "profile").problem,
            "the profile holds the control byte 0x1B at offset 6: it is not a YAML text file");
}

TEST_F(DataFile, TheParameterLoaderUsesIt) {
  ParamDb db = ParamDb::builtin();
  try {
    db.apply_overlay_file(dir_);
    FAIL() << "a directory was accepted";
  } catch (const ParamFileError& e) {
    EXPECT_EQ(std::string(e.what()), dir_.string() + ": is a directory, not a parameter file");
    EXPECT_EQ(e.kind(), i20::ErrorKind::BadInput);
  }
  const auto big = sized("big.yaml", 126u << 20);
  try {
    db.apply_overlay_file(big);
    FAIL() << "a 126 MB overlay was accepted";
  } catch (const ParamFileError& e) {
    EXPECT_EQ(std::string(e.what()),
              big.string() +
                  ": the parameter file is larger than 1048576 bytes, the limit for it (a "
                  "real one is a few KB)");
  }
  EXPECT_THROW(ParamDb::load_file(write("nul.yaml", std::string("parameters: []\0", 15))), ParamFileError);
}

}  // namespace
