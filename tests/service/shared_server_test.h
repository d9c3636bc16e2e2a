// A test suite that shares one tod_server: started once with Derived::ServerArgs() on the
// fixture's tiny bundle before the suite's first test, killed after its last. A test fails, not
// skips, when the server is not serving (REQUIRE_MODEL): a broken fixture must not turn the
// service tests green.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "tests/service/server_harness.h"

namespace tod::server::testing {

template <typename Derived>
class SharedServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (TestModel().empty() || !std::filesystem::exists(BinaryPath("tod_server"))) return;
    server_ = ServerProcess::Start(TestModel(), Derived::ServerArgs());
    ready_ = server_->WaitReady();
  }
  static void TearDownTestSuite() { server_.reset(); }
  // Derived SetUp()s call this first and return when it failed (HasFatalFailure()).
  void SetUp() override {
    REQUIRE_MODEL();
    ASSERT_TRUE(ready_) << server_->Log();
  }

  static inline std::unique_ptr<ServerProcess> server_;
  static inline bool ready_ = false;
};

}  // namespace tod::server::testing
