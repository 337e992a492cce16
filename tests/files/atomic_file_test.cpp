// SPDX-License-Identifier: GPL-2.0-or-later
// files::write_file replaces a regular file only, even when what stands at the name changed
// after the command's early check (check_output_file) ran.
#include "files/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "error/error.hpp"

namespace fs = std::filesystem;
using namespace i20;

namespace {

class Folder {
 public:
  Folder() {
    std::string pattern = (fs::temp_directory_path() / "i20-files-XXXXXX").string();
    path_ = ::mkdtemp(pattern.data());
  }
  ~Folder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  fs::path operator/(const std::string& name) const { return path_ / name; }
  int entries() const {
    int n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(path_)) ++n;
    return n;
  }

 private:
  fs::path path_;
};

std::string read(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(AtomicFile, ReplaceReplacesARegularFile) {
  Folder dir;
  std::ofstream(dir / "a.txt") << "old\n";
  files::write_file(dir / "a.txt", "new\n", files::Existing::Replace);
  EXPECT_EQ(read(dir / "a.txt"), "new\n");
  EXPECT_EQ(dir.entries(), 1);
}

TEST(AtomicFile, ReplaceNeverReplacesAFifoOrALinkAndLeavesNoTemporaryFile) {
  Folder dir;
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  try {
    files::write_file(dir / "fifo", "text\n", files::Existing::Replace);
    FAIL() << "replaced a FIFO";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("it is a FIFO, not a regular file; nothing was replaced"),
              std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(dir / "fifo")));

  std::ofstream(dir / "target") << "kept\n";
  fs::create_symlink(dir / "target", dir / "link");
  EXPECT_THROW(files::write_file(dir / "link", "text\n", files::Existing::Replace), OutputError);
  EXPECT_TRUE(fs::is_symlink(dir / "link"));
  EXPECT_EQ(read(dir / "target"), "kept\n");
  EXPECT_EQ(dir.entries(), 3) << "no temporary file is left";
}

TEST(AtomicFile, NotARegularFileNamesWhatStandsThere) {
  Folder dir;
  EXPECT_EQ(files::not_a_regular_file(dir / "absent"), "");
  std::ofstream(dir / "file") << "x";
  EXPECT_EQ(files::not_a_regular_file(dir / "file"), "");
  EXPECT_EQ(files::not_a_regular_file("/dev/null"), "a character device");
  fs::create_directory(dir / "sub");
  EXPECT_EQ(files::not_a_regular_file(dir / "sub"), "a folder");
}
