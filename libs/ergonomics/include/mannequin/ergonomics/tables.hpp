#pragma once
/// \file tables.hpp
/// \brief The score tables of RULA (McAtamney & Corlett 1993, Applied Ergonomics 24(2):91–99, Tables A, B, C)
/// and REBA (Hignett & McAtamney 2000, Applied Ergonomics 31(2):201–205, Tables A, B, C), as data, with
/// checked lookups. Indices in the comments are the 1-based scores of the sheets.

namespace mannequin::ergonomics {

/// RULA Table A [upper arm 1–6][lower arm 1–3][wrist 1–4][wrist twist 1–2] → posture score A.
inline constexpr int kRulaTableA[6][3][4][2] = {
    {{{1, 2}, {2, 2}, {2, 3}, {3, 3}}, {{2, 2}, {2, 2}, {3, 3}, {3, 3}}, {{2, 3}, {3, 3}, {3, 3}, {4, 4}}},
    {{{2, 3}, {3, 3}, {3, 4}, {4, 4}}, {{3, 3}, {3, 3}, {3, 4}, {4, 4}}, {{3, 4}, {4, 4}, {4, 4}, {5, 5}}},
    {{{3, 3}, {4, 4}, {4, 4}, {5, 5}}, {{3, 4}, {4, 4}, {4, 4}, {5, 5}}, {{4, 4}, {4, 4}, {4, 5}, {5, 5}}},
    {{{4, 4}, {4, 4}, {4, 5}, {5, 5}}, {{4, 4}, {4, 4}, {4, 5}, {5, 5}}, {{4, 4}, {4, 5}, {5, 5}, {6, 6}}},
    {{{5, 5}, {5, 5}, {5, 6}, {6, 7}}, {{5, 6}, {6, 6}, {6, 7}, {7, 7}}, {{6, 6}, {6, 7}, {7, 7}, {7, 8}}},
    {{{7, 7}, {7, 7}, {7, 8}, {8, 9}}, {{8, 8}, {8, 8}, {8, 9}, {9, 9}}, {{9, 9}, {9, 9}, {9, 9}, {9, 9}}},
};

/// RULA Table B [neck 1–6][trunk 1–6][legs 1–2] → posture score B.
inline constexpr int kRulaTableB[6][6][2] = {
    {{1, 3}, {2, 3}, {3, 4}, {5, 5}, {6, 6}, {7, 7}},
    {{2, 3}, {2, 3}, {4, 5}, {5, 5}, {6, 7}, {7, 7}},
    {{3, 3}, {3, 4}, {4, 5}, {5, 6}, {6, 7}, {7, 7}},
    {{5, 5}, {5, 6}, {6, 7}, {7, 7}, {7, 7}, {8, 8}},
    {{7, 7}, {7, 7}, {7, 8}, {8, 8}, {8, 8}, {8, 8}},
    {{8, 8}, {8, 8}, {8, 8}, {8, 9}, {9, 9}, {9, 9}},
};

/// RULA Table C [score C 1–8+][score D 1–7+] → grand score (1–7).
inline constexpr int kRulaTableC[8][7] = {
    {1, 2, 3, 3, 4, 5, 5}, {2, 2, 3, 4, 4, 5, 5}, {3, 3, 3, 4, 4, 5, 6}, {3, 3, 3, 4, 5, 6, 6},
    {4, 4, 4, 5, 6, 7, 7}, {4, 4, 5, 6, 6, 7, 7}, {5, 5, 6, 6, 7, 7, 7}, {5, 5, 6, 7, 7, 7, 7},
};

/// REBA Table A [trunk 1–5][neck 1–3][legs 1–4] → score from Table A.
inline constexpr int kRebaTableA[5][3][4] = {
    {{1, 2, 3, 4}, {1, 2, 3, 4}, {3, 3, 5, 6}},
    {{2, 3, 4, 5}, {3, 4, 5, 6}, {4, 5, 6, 7}},
    {{2, 4, 5, 6}, {4, 5, 6, 7}, {5, 6, 7, 8}},
    {{3, 5, 6, 7}, {5, 6, 7, 8}, {6, 7, 8, 9}},
    {{4, 6, 7, 8}, {6, 7, 8, 9}, {7, 8, 9, 9}},
};

/// REBA Table B [upper arm 1–6][lower arm 1–2][wrist 1–3] → score from Table B.
inline constexpr int kRebaTableB[6][2][3] = {
    {{1, 2, 2}, {1, 2, 3}}, {{1, 2, 3}, {2, 3, 4}}, {{3, 4, 5}, {4, 5, 5}},
    {{4, 5, 5}, {5, 6, 7}}, {{6, 7, 8}, {7, 8, 8}}, {{7, 8, 8}, {8, 9, 9}},
};

/// REBA Table C [score A 1–12][score B 1–12] → score C.
inline constexpr int kRebaTableC[12][12] = {
    {1, 1, 1, 2, 3, 3, 4, 5, 6, 7, 7, 7},          {1, 2, 2, 3, 4, 4, 5, 6, 6, 7, 7, 8},
    {2, 3, 3, 3, 4, 5, 6, 7, 7, 8, 8, 8},          {3, 4, 4, 4, 5, 6, 7, 8, 8, 9, 9, 9},
    {4, 4, 4, 5, 6, 7, 8, 8, 9, 9, 9, 9},          {6, 6, 6, 7, 8, 8, 9, 9, 10, 10, 10, 10},
    {7, 7, 7, 8, 9, 9, 9, 10, 10, 11, 11, 11},     {8, 8, 8, 9, 10, 10, 10, 10, 10, 11, 11, 11},
    {9, 9, 9, 10, 10, 10, 11, 11, 11, 12, 12, 12}, {10, 10, 10, 11, 11, 11, 11, 12, 12, 12, 12, 12},
    {11, 11, 11, 11, 12, 12, 12, 12, 12, 12, 12, 12}, {12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12},
};

// Checked lookups, 1-based scores as on the sheets. Part scores that the adjustments push past the
// table's last row (a RULA wrist 3 + 1 deviation is 4, the last row; an upper arm 4 + 1 + 1 = 6, the
// last row) are in range by construction; the C tables' "8+" / "7+" / "12" rows and columns clamp
// larger sums, as the sheets do. Any score below 1, or above the last row of a part's table (where the
// sheet has no "+"), throws std::out_of_range naming the table and the argument.
int rulaTableA(int upper_arm, int lower_arm, int wrist, int wrist_twist);
int rulaTableB(int neck, int trunk, int legs);
int rulaTableC(int score_c, int score_d);  ///< score_c ≥ 8 reads row 8+, score_d ≥ 7 reads column 7+
int rebaTableA(int trunk, int neck, int legs);
int rebaTableB(int upper_arm, int lower_arm, int wrist);
int rebaTableC(int score_a, int score_b);  ///< scores ≥ 12 read row/column 12

}  // namespace mannequin::ergonomics
