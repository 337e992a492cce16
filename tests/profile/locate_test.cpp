// SPDX-License-Identifier: GPL-2.0-or-later
// Finding a profile by name (`i20 profile apply line-120v` from any directory): the path
// itself first, then the search directories in order, NAME or NAME.yaml; a miss names
// every place that was tried.
#include "profile/locate.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

using namespace i20::profile;
namespace fs = std::filesystem;

namespace {

class ProfileLocate : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("i20-locate-" + std::to_string(std::random_device{}()));
    fs::create_directories(root_ / "first");
    fs::create_directories(root_ / "second");
  }
  void TearDown() override { fs::remove_all(root_); }

  fs::path touch(const std::string& relative) {
    const fs::path path = root_ / relative;
    std::ofstream(path) << "name: x\n";
    return path;
  }
  std::vector<SearchDir> dirs() const {
    return {{root_ / "first", "$I20_PROFILE_PATH"}, {root_ / "second", "installed profiles"}};
  }

  fs::path root_;
};

}  // namespace

TEST_F(ProfileLocate, AnExistingPathWinsOverTheSearchDirectories) {
  const fs::path here = touch("line-120v.yaml");
  touch("first/line-120v.yaml");
  EXPECT_EQ(locate_profile(here.string(), dirs()), here);
}

TEST_F(ProfileLocate, NamesAreSearchedInOrderWithOrWithoutYaml) {
  touch("second/line-120v.yaml");
  EXPECT_EQ(locate_profile("line-120v", dirs()), root_ / "second" / "line-120v.yaml");
  EXPECT_EQ(locate_profile("line-120v.yaml", dirs()), root_ / "second" / "line-120v.yaml");
  touch("first/line-120v.yaml");  // earlier in the list: $I20_PROFILE_PATH before installed
  EXPECT_EQ(locate_profile("line-120v", dirs()), root_ / "first" / "line-120v.yaml");
}

TEST_F(ProfileLocate, AMissNamesEveryPlaceTried) {
  try {
    locate_profile("nosuch", dirs());
    FAIL() << "expected ProfileNotFound";
  } catch (const ProfileNotFound& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("profile 'nosuch' not found"), std::string::npos) << what;
    EXPECT_NE(what.find((root_ / "first" / "nosuch").string() + "[.yaml] ($I20_PROFILE_PATH)"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find((root_ / "second" / "nosuch").string() + "[.yaml] (installed profiles)"),
              std::string::npos)
        << what;
    EXPECT_LT(what.find("first"), what.find("second")) << "in search order";
    EXPECT_EQ(e.kind(), i20::ErrorKind::BadInput);
  }
}

TEST_F(ProfileLocate, APathWithADirectoryIsNotSearchedFor) {
  touch("first/line-120v.yaml");
  EXPECT_THROW(locate_profile("elsewhere/line-120v", dirs()), ProfileNotFound);
  EXPECT_THROW(locate_profile("", dirs()), ProfileNotFound);
}

TEST_F(ProfileLocate, NamesOfferedAreTheYamlFilesOnce) {
  touch("first/a.yaml");
  touch("first/README.md");
  touch("second/a.yaml");
  touch("second/b.yaml");
  EXPECT_EQ(profile_names(dirs()), (std::vector<std::string>{"a", "b"}));
}
