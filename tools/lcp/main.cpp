// mannequin-lcp: solve an LCP read from a plain-text file (format in docs/lcp.md).

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "mannequin/core/main.hpp"
#include "mannequin/lcp/io.hpp"
#include "mannequin/lcp/lemke.hpp"
#include "mannequin/lcp/pgs.hpp"
#include "mannequin/lcp/structured.hpp"

using namespace mannequin::lcp;

namespace {

// JSON string escaping
std::string quote(const std::string& s) {
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", ch);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string num(double v) {
  if (!std::isfinite(v)) return "0";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// the four statuses of the file interface
const char* publicStatus(LcpStatus s) {
  switch (s) {
    case LcpStatus::Solved: return "solved";
    case LcpStatus::NoSolution: return "no_solution";
    case LcpStatus::PivotLimit: return "pivot_limit";
    default: return "invalid";
  }
}

int report(bool json, const char* status, const Eigen::VectorXd& z, int pivots, double compl_,
           const LcpResiduals* res, const std::string& message, int code) {
  if (json) {
    std::string zs = "[";
    for (Index i = 0; i < z.size(); ++i) zs += (i ? ", " : "") + num(z[i]);
    zs += "]";
    std::cout << "{\"status\": " << quote(status) << ", \"z\": " << zs << ", \"pivots\": " << pivots
              << ", \"complementarity\": " << num(compl_) << ", \"message\": " << quote(message)
              << "}\n";
  } else {
    std::cout << "status: " << status << "\n"
              << "pivots/iterations: " << pivots << "\n"
              << "z:";
    for (Index i = 0; i < z.size(); ++i) std::cout << " " << num(z[i]);
    std::cout << "\n";
    if (res) {
      std::cout << "max(-w): " << num(res->max_neg_w) << "\nmax(-z): " << num(res->max_neg_z)
                << "\n|w^T z|: " << num(res->complementarity) << "\n";
    }
    std::cout << "message: " << message << "\n";
  }
  return code;
}

int run(const std::string& file, const std::string& solver, bool json);

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mannequin-lcp: solve 0 <= M z + q _|_ z >= 0 read from a text file"};
  app.require_subcommand(1);
  auto* solve = app.add_subcommand("solve", "solve the LCP in FILE");
  std::string file, solver = "lemke";
  bool json = false;
  solve->add_option("FILE", file, "n, then M row by row, then q; '#' comments")->required();
  solve->add_option("--solver", solver, "lemke | pgs | structured")
      ->check(CLI::IsMember({"lemke", "pgs", "structured"}));
  solve->add_flag("--json", json, "print one JSON object");
  return mannequin::core::runMain(app, argc, argv, [&] { return run(file, solver, json); });
}

namespace {

int run(const std::string& file, const std::string& solver, bool json) {
  // read and parse
  std::ifstream in(file);
  if (!in) return report(json, "invalid", {}, 0, 0.0, nullptr, "cannot open " + file, 2);
  std::stringstream buf;
  buf << in.rdbuf();
  LcpProblem problem;
  std::string error;
  if (!parseLcpText(buf.str(), problem, error)) {
    return report(json, "invalid", {}, 0, 0.0, nullptr, file + ": " + error, 2);
  }

  // solve
  LcpResult r;
  std::string note;
  if (solver == "lemke") {
    LemkeWorkspace ws;
    r = solveLemke(problem, ws);
  } else if (solver == "pgs") {
    PgsWorkspace ws;
    r = solvePgs(problem, ws);
  } else {
    Eigen::MatrixXd A;
    if (const char* err = factorPsd(problem.M, A)) {
      return report(json, "invalid", {}, 0, 0.0, nullptr,
                    std::string("structured solver needs a symmetric PSD M = A A^T: ") + err, 2);
    }
    StructuredWorkspace ws;
    r = solveStructured(StructuredProblem{A, problem.q}, ws);
    note = " (M factored as A A^T, rank " + std::to_string(A.cols()) + ")";
    // residuals against the original M
    r.w = problem.M * r.z + problem.q;
    r.residuals = computeResiduals(problem.q, r.z, r.w);
  }
  const int code = r.status == LcpStatus::Solved ? 0 : (r.status == LcpStatus::Invalid ? 2 : 1);
  return report(json, publicStatus(r.status), r.z, r.pivots, r.residuals.complementarity,
                &r.residuals, std::string(r.message) + note, code);
}

}  // namespace
