// A fresh scratch directory per test for the unit tests that write files.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

// `root`/<suite>_<test> under the working directory (ctest: the build tree), emptied.
inline std::filesystem::path fresh_test_dir(const std::string& root) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::path(root) / (std::string(info->test_suite_name()) + "_" + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}
