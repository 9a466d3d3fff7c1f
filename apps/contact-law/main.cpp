// contact-law: the Maugis–Dugdale sphere–plane law (kernels/maugis_dugdale.hpp) for one material and
// radius, tabulated for given contact radii (--a) and/or geometric overlaps (--delta, negative: gap), as CSV
// on stdout in the order the values were given. No scene file, no output folder, no Kokkos run-time.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "kernels/maugis_dugdale.hpp"

namespace {

struct Options {
  double E = 800e3;    // Pa, paper Table 1
  double nu = 0.4;     // paper Table 1
  double W = 1e-3;     // J/m^2, paper Table 1 (Hategan set)
  double h0 = 20e-9;   // m, paper Table 1
  double R = 3.25e-6;  // m, paper Table 1 (sphered cell)
  std::vector<double> a, delta;
};

// One line on stderr naming the option, its value and the allowed range; the caller exits 2.
bool check(bool ok, const std::string& option, double value, const std::string& allowed) {
  if (ok) return true;
  std::ostringstream s;
  s << "contact-law: error: " << option << " = " << value << " is out of range (allowed " << allowed << ")";
  std::cerr << s.str() << '\n';
  return false;
}

std::string g(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

bool validate(const Options& o) {
  // The scene's ranges (cortex.E_Pa from 1 Pa, contact.W_J_per_m2, contact.h0_m, mesh.radius_m): the law is
  // solved to full precision there; far outside (E = 1e-300 Pa, h0 = 1e-200 m, W = 1e300 J/m²) its terms
  // overflow or underflow and it printed inf or empty loads (session 40).
  bool ok = check(o.E >= 1 && o.E <= 1e9, "--E", o.E, "1 <= E <= 1e9 Pa") &&
            check(o.nu >= 0 && o.nu <= 0.5, "--nu", o.nu, "0 <= nu <= 0.5") &&
            check(o.W >= 0 && o.W <= 1, "--W", o.W, "0 <= W <= 1 J/m^2") &&
            check(o.h0 >= 1e-12 && o.h0 <= 1e-6, "--h0", o.h0, "1e-12 <= h0 <= 1e-6 m") &&
            check(o.R >= 1e-9 && o.R <= 1e-3, "--R", o.R, "1e-9 <= R <= 1e-3 m");
  for (const double a : o.a) ok = ok && check(a >= 0 && a <= o.R, "--a", a, "0 <= a <= R = " + g(o.R) + " m");
  for (const double d : o.delta)
    ok = ok && check(std::isfinite(d) && d <= o.R, "--delta", d, "delta <= R = " + g(o.R) + " m");
  if (ok && o.a.empty() && o.delta.empty()) {
    std::cerr << "contact-law: error: no --a or --delta given (at least one value is required)\n";
    return false;
  }
  return ok;
}

// A CSV field: empty where the quantity is undefined (NaN), never "nan", "inf" or "-0".
std::string field(double v) {
  if (std::isnan(v)) return "";
  char b[32];
  std::snprintf(b, sizeof b, "%.10g", v + 0.0);
  return b;
}

void print_row(const dcm::MdState& st, const Options& o, const dcm::MdMaterial& mat) {
  const double L = dcm::md_length_unit(mat, o.R);
  const double lambda = dcm::md_lambda(mat, o.R);
  const double force_unit = dcm::kMdPi * mat.W * o.R;
  const double m = st.a > 0 ? st.c / st.a : NAN;  // the gap branch (a = 0): m = c/a is undefined
  const double values[] = {
      st.a, st.delta, m, st.c, lambda, L > 0 ? st.a / L : NAN, force_unit > 0 ? st.P / force_unit : NAN,
      st.P};
  std::string line;
  for (const double v : values) line += (line.empty() ? "" : ",") + field(v);
  std::printf("%s\n", line.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app(
      "contact-law: the Maugis-Dugdale law of a sphere (radius R) on a rigid plane, one CSV row per --a or\n"
      "--delta value (in the order given):\n  a_m,delta_m,m,c_m,lambda,Abar,Pbar,P_N\n"
      "a contact radius, delta geometric overlap (a^2 = 2 R delta - delta^2; negative: gap), m = c/a,\n"
      "c adhesive radius, lambda Maugis' parameter, Abar = a/(pi W R^2/K)^(1/3), Pbar = P/(pi W R),\n"
      "P net load (repulsive > 0). In the gap branch a = 0 and m is empty (undefined; c is 0 beyond h0).\n"
      "With W = 0 (Hertz) Abar and Pbar are undefined: empty fields (also where W is so small, below\n"
      "~1e-300, that their units underflow).\n"
      "Model and checks: docs/model/contact.md",
      "contact-law");
  app.footer(
      "Example:\n  contact-law --W 1e-3 --h0 20e-9 --R 3.25e-6 --a 1e-7 --a 2e-7 --delta=-5e-9\n"
      "Exit codes: 0 success, 2 bad input (one line on stderr).");
  app.add_option("--E", o.E, "Young's modulus of the cell cortex (Pa), 1 <= E <= 1e9")->capture_default_str();
  app.add_option("--nu", o.nu, "Poisson ratio, 0 <= nu <= 0.5 (as cortex.nu)")->capture_default_str();
  app.add_option("--W", o.W, "Work of adhesion (J/m^2), 0 <= W <= 1 (0: Hertz)")->capture_default_str();
  app.add_option("--h0", o.h0, "Range of the Dugdale stress (m), 1e-12 <= h0 <= 1e-6; sigma0 = W/h0")
      ->capture_default_str();
  app.add_option("--R", o.R, "Reduced radius of the sphere (m), 1e-9 <= R <= 1e-3")->capture_default_str();
  app.add_option("--a", o.a, "Contact radius (m), 0 <= a <= R (repeatable)")->allow_extra_args(false);
  app.add_option("--delta", o.delta,
                 "Geometric overlap (m), <= R; negative: gap to the plane, no force beyond -h0 (repeatable; "
                 "write negative values as --delta=-5e-9)")
      ->allow_extra_args(false);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::cerr << "contact-law: error: " << e.what() << " (see --help)\n";
    return 2;
  }
  if (!validate(o)) return 2;

  const dcm::MdMaterial mat = dcm::md_material(o.E, o.nu, o.W, o.h0);
  std::printf("a_m,delta_m,m,c_m,lambda,Abar,Pbar,P_N\n");
  // Rows in the order the values appeared on the command line.
  std::size_t ia = 0, id = 0;
  for (const CLI::Option* opt : app.parse_order()) {
    if (opt->get_name() == "--a" && ia < o.a.size())
      print_row(dcm::md_state_from_radius(o.a[ia++], o.R, mat), o, mat);
    if (opt->get_name() == "--delta" && id < o.delta.size())
      print_row(dcm::md_state_from_overlap(o.delta[id++], o.R, mat), o, mat);
  }
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {  // the table is the output: a lost write is an error
    std::cerr << "contact-law: error: standard output: the write failed (a full disk or a closed file?)\n";
    return 2;
  }
  return 0;
}
