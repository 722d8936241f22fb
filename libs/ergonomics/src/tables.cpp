#include "mannequin/ergonomics/tables.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace mannequin::ergonomics {

namespace {
void check(const char* table, const char* what, int v, int hi) {
  if (v < 1 || v > hi)
    throw std::out_of_range(std::string(table) + ": " + what + " score " + std::to_string(v) + " is outside 1.." +
                            std::to_string(hi));
}
int clampLow(const char* table, const char* what, int v) {
  if (v < 1)
    throw std::out_of_range(std::string(table) + ": " + what + " score " + std::to_string(v) + " is below 1");
  return v;
}
}  // namespace

int rulaTableA(int upper_arm, int lower_arm, int wrist, int wrist_twist) {
  check("RULA Table A", "upper arm", upper_arm, 6);
  check("RULA Table A", "lower arm", lower_arm, 3);
  check("RULA Table A", "wrist", wrist, 4);
  check("RULA Table A", "wrist twist", wrist_twist, 2);
  return kRulaTableA[upper_arm - 1][lower_arm - 1][wrist - 1][wrist_twist - 1];
}

int rulaTableB(int neck, int trunk, int legs) {
  check("RULA Table B", "neck", neck, 6);
  check("RULA Table B", "trunk", trunk, 6);
  check("RULA Table B", "legs", legs, 2);
  return kRulaTableB[neck - 1][trunk - 1][legs - 1];
}

int rulaTableC(int score_c, int score_d) {
  const int c = std::min(clampLow("RULA Table C", "wrist/arm (C)", score_c), 8);
  const int d = std::min(clampLow("RULA Table C", "neck/trunk/leg (D)", score_d), 7);
  return kRulaTableC[c - 1][d - 1];
}

int rebaTableA(int trunk, int neck, int legs) {
  check("REBA Table A", "trunk", trunk, 5);
  check("REBA Table A", "neck", neck, 3);
  check("REBA Table A", "legs", legs, 4);
  return kRebaTableA[trunk - 1][neck - 1][legs - 1];
}

int rebaTableB(int upper_arm, int lower_arm, int wrist) {
  check("REBA Table B", "upper arm", upper_arm, 6);
  check("REBA Table B", "lower arm", lower_arm, 2);
  check("REBA Table B", "wrist", wrist, 3);
  return kRebaTableB[upper_arm - 1][lower_arm - 1][wrist - 1];
}

int rebaTableC(int score_a, int score_b) {
  const int a = std::min(clampLow("REBA Table C", "score A", score_a), 12);
  const int b = std::min(clampLow("REBA Table C", "score B", score_b), 12);
  return kRebaTableC[a - 1][b - 1];
}

}  // namespace mannequin::ergonomics
