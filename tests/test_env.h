// Locations the tests need, fixed at configure time (tests/CMakeLists.txt); an environment
// variable of the same name overrides each: TOD_BIN_DIR, TOD_SOURCE_DIR, TOD_TEST_DATA,
// TOD_TEST_MODEL.
#pragma once

#include <cstdlib>
#include <string>

namespace tod::testing_env {

inline std::string Get(const char* name, const char* configured) {
  const char* value = std::getenv(name);
  return value != nullptr && *value != '\0' ? value : configured;
}

inline std::string BinDir() { return Get("TOD_BIN_DIR", TOD_DEFAULT_BIN_DIR); }
inline std::string SourceDir() { return Get("TOD_SOURCE_DIR", TOD_DEFAULT_SOURCE_DIR); }
inline std::string TestData() { return Get("TOD_TEST_DATA", TOD_DEFAULT_TEST_DATA); }
inline std::string TestModel() { return Get("TOD_TEST_MODEL", TOD_DEFAULT_TEST_MODEL); }

}  // namespace tod::testing_env
