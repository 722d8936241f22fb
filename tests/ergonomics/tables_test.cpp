// The score tables: every corner against the published sheets (McAtamney & Corlett 1993 Tables A–C,
// Hignett & McAtamney 2000 Tables A–C, read off the sheets by hand), the clamping of the C tables' last
// row/column, out-of-range scores refused, and monotonicity (a worse part never lowers a table's result).
#include "mannequin/ergonomics/tables.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

using namespace mannequin::ergonomics;

TEST(RulaTables, CornersOfTableA) {
  // (upper arm, lower arm, wrist, twist) at the extremes of each axis
  EXPECT_EQ(rulaTableA(1, 1, 1, 1), 1);
  EXPECT_EQ(rulaTableA(1, 1, 1, 2), 2);
  EXPECT_EQ(rulaTableA(1, 1, 4, 1), 3);
  EXPECT_EQ(rulaTableA(1, 1, 4, 2), 3);
  EXPECT_EQ(rulaTableA(1, 3, 1, 1), 2);
  EXPECT_EQ(rulaTableA(1, 3, 1, 2), 3);
  EXPECT_EQ(rulaTableA(1, 3, 4, 1), 4);
  EXPECT_EQ(rulaTableA(1, 3, 4, 2), 4);
  EXPECT_EQ(rulaTableA(6, 1, 1, 1), 7);
  EXPECT_EQ(rulaTableA(6, 1, 1, 2), 7);
  EXPECT_EQ(rulaTableA(6, 1, 4, 1), 8);
  EXPECT_EQ(rulaTableA(6, 1, 4, 2), 9);
  EXPECT_EQ(rulaTableA(6, 3, 1, 1), 9);
  EXPECT_EQ(rulaTableA(6, 3, 1, 2), 9);
  EXPECT_EQ(rulaTableA(6, 3, 4, 1), 9);
  EXPECT_EQ(rulaTableA(6, 3, 4, 2), 9);
  // an inside cell: upper arm 3, lower arm 2, wrist 3, twist 1
  EXPECT_EQ(rulaTableA(3, 2, 3, 1), 4);
  EXPECT_EQ(rulaTableA(5, 2, 4, 2), 7);
}

TEST(RulaTables, CornersOfTablesBAndC) {
  // Table B (neck, trunk, legs)
  EXPECT_EQ(rulaTableB(1, 1, 1), 1);
  EXPECT_EQ(rulaTableB(1, 1, 2), 3);
  EXPECT_EQ(rulaTableB(1, 6, 1), 7);
  EXPECT_EQ(rulaTableB(1, 6, 2), 7);
  EXPECT_EQ(rulaTableB(6, 1, 1), 8);
  EXPECT_EQ(rulaTableB(6, 1, 2), 8);
  EXPECT_EQ(rulaTableB(6, 6, 1), 9);
  EXPECT_EQ(rulaTableB(6, 6, 2), 9);
  EXPECT_EQ(rulaTableB(2, 3, 1), 4);
  // Table C (score C 1..8+, score D 1..7+)
  EXPECT_EQ(rulaTableC(1, 1), 1);
  EXPECT_EQ(rulaTableC(1, 7), 5);
  EXPECT_EQ(rulaTableC(8, 1), 5);
  EXPECT_EQ(rulaTableC(8, 7), 7);
  EXPECT_EQ(rulaTableC(2, 1), 2);
  EXPECT_EQ(rulaTableC(4, 3), 3);
  // "8+" and "7+": larger sums read the last row/column
  EXPECT_EQ(rulaTableC(13, 1), 5);
  EXPECT_EQ(rulaTableC(1, 11), 5);
  EXPECT_EQ(rulaTableC(13, 11), 7);
}

TEST(RebaTables, CornersOfTablesABC) {
  // Table A (trunk, neck, legs)
  EXPECT_EQ(rebaTableA(1, 1, 1), 1);
  EXPECT_EQ(rebaTableA(1, 1, 4), 4);
  EXPECT_EQ(rebaTableA(1, 3, 1), 3);
  EXPECT_EQ(rebaTableA(1, 3, 4), 6);
  EXPECT_EQ(rebaTableA(5, 1, 1), 4);
  EXPECT_EQ(rebaTableA(5, 1, 4), 8);
  EXPECT_EQ(rebaTableA(5, 3, 1), 7);
  EXPECT_EQ(rebaTableA(5, 3, 4), 9);
  EXPECT_EQ(rebaTableA(3, 2, 2), 5);
  // Table B (upper arm, lower arm, wrist)
  EXPECT_EQ(rebaTableB(1, 1, 1), 1);
  EXPECT_EQ(rebaTableB(1, 1, 3), 2);
  EXPECT_EQ(rebaTableB(1, 2, 1), 1);
  EXPECT_EQ(rebaTableB(1, 2, 3), 3);
  EXPECT_EQ(rebaTableB(6, 1, 1), 7);
  EXPECT_EQ(rebaTableB(6, 1, 3), 8);
  EXPECT_EQ(rebaTableB(6, 2, 1), 8);
  EXPECT_EQ(rebaTableB(6, 2, 3), 9);
  EXPECT_EQ(rebaTableB(4, 2, 3), 7);
  // Table C (score A, score B)
  EXPECT_EQ(rebaTableC(1, 1), 1);
  EXPECT_EQ(rebaTableC(1, 12), 7);
  EXPECT_EQ(rebaTableC(12, 1), 12);
  EXPECT_EQ(rebaTableC(12, 12), 12);
  EXPECT_EQ(rebaTableC(6, 1), 6);
  EXPECT_EQ(rebaTableC(3, 6), 5);
  EXPECT_EQ(rebaTableC(15, 14), 12);  // beyond 12 reads the last row and column
}

TEST(Tables, OutOfRangeScoresAreRefusedByName) {
  EXPECT_THROW(rulaTableA(0, 1, 1, 1), std::out_of_range);
  EXPECT_THROW(rulaTableA(7, 1, 1, 1), std::out_of_range);
  EXPECT_THROW(rulaTableA(1, 4, 1, 1), std::out_of_range);
  EXPECT_THROW(rulaTableA(1, 1, 5, 1), std::out_of_range);
  EXPECT_THROW(rulaTableA(1, 1, 1, 3), std::out_of_range);
  EXPECT_THROW(rulaTableB(1, 7, 1), std::out_of_range);
  EXPECT_THROW(rulaTableB(1, 1, 3), std::out_of_range);
  EXPECT_THROW(rulaTableC(0, 1), std::out_of_range);
  EXPECT_THROW(rebaTableA(6, 1, 1), std::out_of_range);
  EXPECT_THROW(rebaTableA(1, 4, 1), std::out_of_range);
  EXPECT_THROW(rebaTableB(1, 3, 1), std::out_of_range);
  EXPECT_THROW(rebaTableC(1, 0), std::out_of_range);
  try {
    rulaTableA(1, 1, 9, 1);
    FAIL();
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("RULA Table A: wrist score 9"), std::string::npos) << e.what();
  }
}

TEST(Tables, AWorsePartNeverLowersTheResult) {
  for (int u = 1; u <= 6; ++u)
    for (int l = 1; l <= 3; ++l)
      for (int w = 1; w <= 4; ++w)
        for (int t = 1; t <= 2; ++t) {
          const int v = rulaTableA(u, l, w, t);
          if (u < 6) { EXPECT_LE(v, rulaTableA(u + 1, l, w, t)) << u << l << w << t; }
          if (l < 3) { EXPECT_LE(v, rulaTableA(u, l + 1, w, t)) << u << l << w << t; }
          if (w < 4) { EXPECT_LE(v, rulaTableA(u, l, w + 1, t)) << u << l << w << t; }
          if (t < 2) { EXPECT_LE(v, rulaTableA(u, l, w, t + 1)) << u << l << w << t; }
        }
  for (int n = 1; n <= 6; ++n)
    for (int t = 1; t <= 6; ++t)
      for (int g = 1; g <= 2; ++g) {
        const int v = rulaTableB(n, t, g);
        if (n < 6) { EXPECT_LE(v, rulaTableB(n + 1, t, g)); }
        if (t < 6) { EXPECT_LE(v, rulaTableB(n, t + 1, g)); }
        if (g < 2) { EXPECT_LE(v, rulaTableB(n, t, g + 1)); }
      }
  for (int c = 1; c <= 9; ++c)
    for (int d = 1; d <= 8; ++d) {
      EXPECT_LE(rulaTableC(c, d), rulaTableC(c + 1, d));
      EXPECT_LE(rulaTableC(c, d), rulaTableC(c, d + 1));
    }
  for (int t = 1; t <= 5; ++t)
    for (int n = 1; n <= 3; ++n)
      for (int g = 1; g <= 4; ++g) {
        const int v = rebaTableA(t, n, g);
        if (t < 5) { EXPECT_LE(v, rebaTableA(t + 1, n, g)); }
        if (n < 3) { EXPECT_LE(v, rebaTableA(t, n + 1, g)); }
        if (g < 4) { EXPECT_LE(v, rebaTableA(t, n, g + 1)); }
      }
  for (int u = 1; u <= 6; ++u)
    for (int l = 1; l <= 2; ++l)
      for (int w = 1; w <= 3; ++w) {
        const int v = rebaTableB(u, l, w);
        if (u < 6) { EXPECT_LE(v, rebaTableB(u + 1, l, w)) << u << l << w; }
        if (l < 2) { EXPECT_LE(v, rebaTableB(u, l + 1, w)) << u << l << w; }
        if (w < 3) { EXPECT_LE(v, rebaTableB(u, l, w + 1)) << u << l << w; }
      }
  for (int a = 1; a <= 12; ++a)
    for (int b = 1; b <= 12; ++b) {
      EXPECT_LE(rebaTableC(a, b), rebaTableC(a + 1, b));
      EXPECT_LE(rebaTableC(a, b), rebaTableC(a, b + 1));
    }
}
