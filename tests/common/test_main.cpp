// The main of every test executable: GoogleTest's, plus a listener that fails a test which logged at error
// level without expecting it (common/error_log.hpp).
#include <gtest/gtest.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <memory>
#include <mutex>
#include <string>

#include "error_log.hpp"

namespace mannequin::testing {
namespace {

int& expecting() {  // depth of the ExpectErrorLog scopes open now
  static int depth = 0;
  return depth;
}

/// Counts error-level messages, and apart those logged outside every ExpectErrorLog scope (keeping the first
/// of them); a sink of spdlog's default logger during each test.
class ErrorCountSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  std::size_t total() {
    std::lock_guard<std::mutex> lock(mutex_);
    return total_;
  }
  std::size_t unexpected() {
    std::lock_guard<std::mutex> lock(mutex_);
    return unexpected_;
  }
  std::string firstUnexpected() {
    std::lock_guard<std::mutex> lock(mutex_);
    return first_;
  }
  void clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    total_ = unexpected_ = 0;
    first_.clear();
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    if (msg.level < spdlog::level::err || msg.level == spdlog::level::off) return;
    ++total_;
    if (expecting() > 0) return;
    if (unexpected_++ == 0) first_.assign(msg.payload.data(), msg.payload.size());
  }
  void flush_() override {}

 private:
  std::size_t total_ = 0, unexpected_ = 0;
  std::string first_;
};

// the one sink of this executable (the listener and ExpectErrorLog share it; test harness state only)
std::shared_ptr<ErrorCountSink>& sink() {
  static std::shared_ptr<ErrorCountSink> s = std::make_shared<ErrorCountSink>();
  return s;
}

class ErrorLogListener final : public ::testing::EmptyTestEventListener {
 public:
  void OnTestStart(const ::testing::TestInfo&) override {
    sink()->clear();
    expecting() = 0;
    logger_ = spdlog::default_logger();
    if (logger_) logger_->sinks().push_back(sink());
  }
  void OnTestEnd(const ::testing::TestInfo&) override {
    if (logger_) {
      auto& sinks = logger_->sinks();
      sinks.erase(std::remove(sinks.begin(), sinks.end(), std::shared_ptr<spdlog::sinks::sink>(sink())), sinks.end());
      logger_.reset();
    }
    const std::size_t n = sink()->unexpected();
    EXPECT_EQ(n, 0u) << "the test logged " << n << " unexpected error-level message(s); the first: \""
                     << sink()->firstUnexpected() << "\" (a test of an error path declares it with "
                     << "mannequin::testing::ExpectErrorLog, tests/common/error_log.hpp)";
  }

 private:
  std::shared_ptr<spdlog::logger> logger_;
};

}  // namespace

ExpectErrorLog::ExpectErrorLog() : before_(sink()->total()) { ++expecting(); }
ExpectErrorLog::~ExpectErrorLog() {
  --expecting();
  EXPECT_GE(sink()->total() - before_, 1u) << "an error-level log was expected in this scope and none came";
}

}  // namespace mannequin::testing

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ::testing::UnitTest::GetInstance()->listeners().Append(new mannequin::testing::ErrorLogListener);
  return RUN_ALL_TESTS();
}
