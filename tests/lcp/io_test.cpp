#include <gtest/gtest.h>

#include "mannequin/lcp/io.hpp"

using namespace mannequin::lcp;

TEST(LcpText, ParsesCommentsAndLayout) {
  LcpProblem p;
  std::string err;
  ASSERT_TRUE(parseLcpText("# murty\n2\n\n2 1\n1 2  # no\n", p, err) == false);
  EXPECT_NE(err.find("line 5"), std::string::npos) << err;
  ASSERT_TRUE(parseLcpText("# murty\n2\n\n2 1\n1 2\n-5 -6\n", p, err)) << err;
  EXPECT_EQ(p.M(1, 0), 1.0);
  EXPECT_EQ(p.q[1], -6.0);
}

TEST(LcpText, ErrorsNameTheLine) {
  LcpProblem p;
  std::string err;
  EXPECT_FALSE(parseLcpText("2\n1 0\n0 x\n1 1\n", p, err));
  EXPECT_NE(err.find("line 3"), std::string::npos) << err;
  EXPECT_FALSE(parseLcpText("2\n1 0\n0 1\n1\n", p, err));
  EXPECT_NE(err.find("line 4"), std::string::npos) << err;
  EXPECT_FALSE(parseLcpText("2\n1 0\n0 1\n1 1\n7\n", p, err));
  EXPECT_NE(err.find("line 5"), std::string::npos) << err;
  EXPECT_FALSE(parseLcpText("2.5\n", p, err));
  EXPECT_NE(err.find("line 1"), std::string::npos) << err;
  EXPECT_FALSE(parseLcpText("1\nnan\n1\n", p, err));
  EXPECT_FALSE(parseLcpText("", p, err));
}
