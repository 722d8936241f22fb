#pragma once
// Every test executable's main (common/test_main.cpp) fails a test during which anything was logged at
// error level or above through spdlog's default logger: an error log is a defect unless the test says it
// expects one. A test of an error path declares it with
//   mannequin::testing::ExpectErrorLog expect;        // at least one error-level message in its scope
// and fails if none came. Messages from child processes (system tests) are not seen here: those tests
// read the child's output themselves.
#include <cstddef>

namespace mannequin::testing {

/// In its scope, error-level logs are expected: the test fails if the scope ends without one.
class ExpectErrorLog {
 public:
  ExpectErrorLog();
  ~ExpectErrorLog();
  ExpectErrorLog(const ExpectErrorLog&) = delete;
  ExpectErrorLog& operator=(const ExpectErrorLog&) = delete;

 private:
  std::size_t before_;
};

}  // namespace mannequin::testing
