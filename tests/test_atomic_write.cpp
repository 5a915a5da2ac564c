// Outputs are never half-written (mfr/core/atomic_file.hpp): every writer goes through
// writeFileAtomically (temporary file in the same folder, fsync, rename). A write failure injected
// mid-file, or the writing process killed mid-file, leaves the previous file intact (or none) and
// no temporary file behind.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include "cli_runner.hpp"
#include "mfr/core/atomic_file.hpp"
#include "mfr/core/image.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/mlp.hpp"
#include "mfr/learn/model_file.hpp"

namespace {

namespace fs = std::filesystem;

class AtomicWrite : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    dir_ = fs::temp_directory_path() / ("mfr_atomic_" + std::to_string(std::random_device{}()) +
                                        "_" + std::to_string(counter++));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    mfr::setWriteFailureInjectionForTests({});
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir() const { return dir_; }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

 private:
  fs::path dir_;
};

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::set<std::string> entries(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

/// Fails every write to `target` once `after` bytes of it are written.
void failWritesTo(const std::string& target, uint64_t after) {
  mfr::setWriteFailureInjectionForTests([target, after](const std::string& path, uint64_t written) {
    return path == target && written >= after;
  });
}

std::string payload(size_t bytes, char seed) {
  std::string s(bytes, '\0');
  for (size_t i = 0; i < bytes; ++i) s[i] = static_cast<char>(seed + i * 31);
  return s;
}

TEST_F(AtomicWrite, WritesAndReplacesAFileLeavingNothingElse) {
  const std::string file = path("out.bin");
  ASSERT_TRUE(mfr::writeFileAtomically(file, "first").ok());
  EXPECT_EQ(readAll(file), "first");
  const std::string big = payload(3 << 20, 'a');  // several chunks
  ASSERT_TRUE(mfr::writeFileAtomically(file, big).ok());
  EXPECT_EQ(readAll(file), big);
  ASSERT_TRUE(mfr::writeFileAtomically(file, "").ok());  // an empty file is a file
  EXPECT_TRUE(fs::exists(file) && fs::file_size(file) == 0);
  EXPECT_EQ(entries(dir()), std::set<std::string>{"out.bin"});
}

TEST_F(AtomicWrite, InjectedFailureMidFileKeepsTheOldFileAndLeavesNoTemporary) {
  const std::string file = path("out.bin");
  const std::string old = payload(1000, 'o');
  ASSERT_TRUE(mfr::writeFileAtomically(file, old).ok());
  failWritesTo(file, 1);  // after the first chunk of three
  auto written = mfr::writeFileAtomically(file, payload(3 << 20, 'n'));
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().message.find(file), std::string::npos) << written.error().message;
  EXPECT_NE(written.error().message.find("write error"), std::string::npos);
  EXPECT_EQ(readAll(file), old);
  EXPECT_EQ(entries(dir()), std::set<std::string>{"out.bin"});
  // a new file that fails is not created at all
  auto fresh = mfr::writeFileAtomically(path("new.bin"), payload(10, 'x'));
  EXPECT_TRUE(fresh.ok());  // another path: not injected
  failWritesTo(path("other.bin"), 0);
  EXPECT_FALSE(mfr::writeFileAtomically(path("other.bin"), payload(10, 'x')).ok());
  EXPECT_EQ(entries(dir()), (std::set<std::string>{"out.bin", "new.bin"}));
}

TEST_F(AtomicWrite, ProcessKilledMidWriteLeavesTheOldFile) {
  const std::string file = path("out.bin");
  const std::string old = payload(5000, 'o');
  ASSERT_TRUE(mfr::writeFileAtomically(file, old).ok());
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // killed (SIGKILL: no clean-up of any kind) after the first MiB of three
    mfr::setWriteFailureInjectionForTests([](const std::string&, uint64_t written) {
      if (written >= (1u << 20)) ::raise(SIGKILL);
      return false;
    });
    ::_exit(mfr::writeFileAtomically(file, payload(3 << 20, 'n')).ok() ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;
  EXPECT_EQ(readAll(file), old);
  // where the file system has O_TMPFILE, the unfinished data never had a name
  const int probe = ::open(dir().c_str(), O_TMPFILE | O_WRONLY, 0600);
  if (probe >= 0) {
    ::close(probe);
    EXPECT_EQ(entries(dir()), std::set<std::string>{"out.bin"});
  } else {
    for (const std::string& name : entries(dir()))
      EXPECT_TRUE(name == "out.bin" || name.rfind(".out.bin.tmp.", 0) == 0) << name;
  }
}

// The temporary name fits wherever the destination's does: a name of NAME_MAX (255) bytes, ASCII
// or multi-byte UTF-8 (the temporary keeps at most 128 bytes of it, cut between characters), is
// written and replaced; a longer name is the file system's refusal, named.
TEST_F(AtomicWrite, WritesAndReplacesFilesWhoseNamesAre255Bytes) {
  std::string utf8 = "x";
  for (int i = 0; i < 127; ++i) utf8 += "\xc3\xa9";  // U+00E9: 2 bytes each
  for (const std::string& name : {std::string(251, 'n') + ".png", utf8}) {
    ASSERT_EQ(name.size(), 255u);
    const std::string file = path(name);
    ASSERT_TRUE(mfr::writeFileAtomically(file, "first").ok());
    auto second = mfr::writeFileAtomically(file, "second");
    ASSERT_TRUE(second.ok()) << second.error().message;
    EXPECT_EQ(readAll(file), "second");
    EXPECT_EQ(entries(dir()), std::set<std::string>{name});
    fs::remove(file);
  }
  auto tooLong = mfr::writeFileAtomically(path(std::string(256, 'n')), "x");
  ASSERT_FALSE(tooLong.ok());
  EXPECT_NE(tooLong.error().message.find("File name too long"), std::string::npos)
      << tooLong.error().message;
}

TEST_F(AtomicWrite, KeepsPermissionsAndWritesSpecialFilesInPlace) {
  const std::string file = path("private.txt");
  ASSERT_TRUE(mfr::writeFileAtomically(file, "a").ok());
  fs::permissions(file, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  ASSERT_TRUE(mfr::writeFileAtomically(file, "b").ok());
  EXPECT_EQ(fs::status(file).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  // /dev/null is written to, not replaced by a regular file
  ASSERT_TRUE(mfr::writeFileAtomically("/dev/null", "discarded").ok());
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  // a missing folder is made, as for every output
  ASSERT_TRUE(mfr::writeFileAtomically(path("new_folder/deeper/x.json"), "{}").ok());
  EXPECT_EQ(readAll(path("new_folder/deeper/x.json")), "{}");
  // errors name the path: a regular file where a folder should be
  ASSERT_TRUE(mfr::writeFileAtomically(path("a_file"), "x").ok());
  auto blocked = mfr::writeFileAtomically(path("a_file/x.json"), "{}");
  ASSERT_FALSE(blocked.ok());
  EXPECT_NE(blocked.error().message.find("a_file/x.json: cannot open for writing"),
            std::string::npos)
      << blocked.error().message;
  auto folder = mfr::writeFileAtomically(dir().string(), "x");
  ASSERT_FALSE(folder.ok());
  EXPECT_NE(folder.error().message.find("is a directory"), std::string::npos);
}

// Every writer of the library goes through it: an injected failure keeps the old file.

TEST_F(AtomicWrite, PngWriterKeepsTheOldImageOnFailure) {
  const std::string file = path("image.png");
  mfr::Image8 image;
  image.width = image.height = 512;
  image.rgba.resize(512 * 512 * 4);
  for (size_t i = 0; i < image.rgba.size(); ++i) image.rgba[i] = static_cast<uint8_t>(i * 7919);
  ASSERT_TRUE(mfr::writePng(file, image).ok());
  const std::string old = readAll(file);
  for (uint8_t& v : image.rgba) v = static_cast<uint8_t>(v + 1);
  failWritesTo(file, 0);
  auto written = mfr::writePng(file, image);
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().message.find(file + ": cannot write PNG"), std::string::npos)
      << written.error().message;
  EXPECT_EQ(readAll(file), old);
  auto back = mfr::readPng(file);  // still the old, complete image
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->width, 512);
  EXPECT_EQ(entries(dir()), std::set<std::string>{"image.png"});
  mfr::setWriteFailureInjectionForTests({});
  ASSERT_TRUE(mfr::writePng(file, image).ok());
  EXPECT_EQ(mfr::readPng(file)->rgba, image.rgba);
}

TEST_F(AtomicWrite, ModelAndDatasetWritersKeepTheOldFileOnFailure) {
  const std::string model = path("m.mfrnn");
  const mfr::learn::Model first{mfr::learn::makeMlp({3, 4, 2}, 1), R"({"v":1})"};
  ASSERT_TRUE(mfr::learn::writeModel(model, first).ok());
  const std::string oldModel = readAll(model);
  failWritesTo(model, 0);
  const mfr::learn::Model second{mfr::learn::makeMlp({3, 4, 2}, 2), R"({"v":2})"};
  EXPECT_FALSE(mfr::learn::writeModel(model, second).ok());
  EXPECT_EQ(readAll(model), oldModel);
  EXPECT_TRUE(mfr::learn::readModel(model).ok());

  const std::string dataset = path("d.mfrds");
  mfr::learn::Dataset data;
  data.scenes = {"procedural:layers"};
  data.metadata = "{}";
  data.samples.resize(100000);  // several MiB: the failure comes mid-file
  ASSERT_TRUE(mfr::learn::writeDataset(dataset, data).ok());
  const std::string oldDataset = readAll(dataset);
  data.samples.resize(200000);
  failWritesTo(dataset, 1);
  auto written = mfr::learn::writeDataset(dataset, data);
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().message.find("dataset " + dataset), std::string::npos)
      << written.error().message;
  EXPECT_EQ(readAll(dataset), oldDataset);
  auto back = mfr::learn::readDataset(dataset);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->samples.size(), 100000u);
  EXPECT_EQ(entries(dir()), (std::set<std::string>{"m.mfrnn", "d.mfrds"}));
}

TEST_F(AtomicWrite, CliOutputsLeaveNoTemporaryFiles) {
  const std::string image = path("r.png"), stats = path("r.json");
  const mfr::test::CliRun r =
      mfr::test::runCli("render procedural:layers --width 32 --height 32 -q -o " + image +
                            " --stats-json " + stats + " --k-map " + path("k.png"),
                        dir());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(readAll(stats).find("\"bytes_used\""), std::string::npos);
  EXPECT_EQ(entries(dir()),
            (std::set<std::string>{"r.png", "r.json", "k.png", "stderr.txt", "stdout.txt"}));
}

}  // namespace
