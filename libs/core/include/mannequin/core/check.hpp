#pragma once
/// \file check.hpp
/// \brief Argument checks at public boundaries (API misuse: the setup tier of docs/architecture.md's
/// error policy). A failed check throws std::invalid_argument whose message names the function, what
/// was checked, what was expected and what it got. Not for the real-time loop's numerical trouble,
/// which returns statuses.
#include <stdexcept>
#include <string>

namespace mannequin::core {

[[noreturn]] inline void argumentSizeError(const char* function, const char* what, long long expected, long long got) {
  throw std::invalid_argument(std::string(function) + ": " + what + " has size " + std::to_string(got) + ", expected " +
                              std::to_string(expected));
}

}  // namespace mannequin::core

/// Throws std::invalid_argument "FUNCTION: WHAT has size GOT, expected EXPECTED" when size != expected.
#define MANNEQUIN_CHECK_ARGUMENT_SIZE(size, expected, what)                                                        \
  do {                                                                                                             \
    const long long mannequin_check_size_ = static_cast<long long>(size);                                         \
    const long long mannequin_check_expected_ = static_cast<long long>(expected);                                 \
    if (mannequin_check_size_ != mannequin_check_expected_)                                                        \
      ::mannequin::core::argumentSizeError(__func__, what, mannequin_check_expected_, mannequin_check_size_);      \
  } while (false)
