#pragma once
/// \file status_printer.hpp
/// \brief The launcher's output: each service's lines prefixed with its name, the launcher's own lines,
/// and the status line — redrawn in place on a terminal, printed as "status | ..." lines otherwise.
#include <cstdio>
#include <string>

namespace mannequin::deploy {

class StatusPrinter {
 public:
  StatusPrinter(std::FILE* out, bool tty, std::size_t name_width) : out_(out), tty_(tty), width_(name_width) {}
  /// "NAME     | line" (clears a status line on screen first).
  void line(const std::string& name, const std::string& text);
  /// "launch   | text".
  void launcher(const std::string& text) { line("launch", text); }
  /// The status: redrawn in place on a tty, a "status | ..." line otherwise.
  void status(const std::string& text);
  /// Removes a status line drawn on a tty.
  void clear();
  bool tty() const { return tty_; }

 private:
  std::FILE* out_;
  bool tty_;
  std::size_t width_;
  bool shown_ = false;
};

}  // namespace mannequin::deploy
