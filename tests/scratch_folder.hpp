// A fresh folder per test under the system temp dir, removed afterwards: `model/` holds the scene
// files a test writes, files beside it in root() are "outside" the scene's folder.
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <random>
#include <string>
#include <system_error>
#include <utility>

namespace mfr::test {

class ScratchFolderTest : public ::testing::Test {
 protected:
  explicit ScratchFolderTest(std::string tag) : tag_(std::move(tag)) {}
  void SetUp() override {
    static std::atomic<int> counter{0};
    root_ = std::filesystem::temp_directory_path() /
            (tag_ + "_" + std::to_string(std::random_device{}()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(root_ / "model");
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(root_, ec);
  }
  std::filesystem::path root() const { return root_; }
  std::filesystem::path model() const { return root_ / "model"; }

 private:
  std::string tag_;
  std::filesystem::path root_;
};

}  // namespace mfr::test
