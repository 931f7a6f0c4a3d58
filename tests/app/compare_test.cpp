// `furrow compare` run as a user would: force traces of two runs in one chart, and its errors.
#include <gtest/gtest.h>

#include <fstream>

#include "tests/app/cli_fixture.hpp"

namespace {

namespace fs = std::filesystem;

class CompareCli : public furrow::cli_test::CliFixture {
 protected:
  CompareCli() : CliFixture("furrow_compare_") {}
  // a run directory whose forces.csv has a plate pushed down 10 mm against a force F0 + k s
  std::string fake_run(const std::string& name, double F0) {
    const fs::path d = dir_ / name;
    fs::create_directories(d);
    std::ofstream f(d / "forces.csv");
    f << "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m\n";
    for (int k = 0; k <= 100; ++k) f << 0.001 * k << ",plate,0.5," << 0.6 - 1e-4 * k << ",0," << F0 + 10.0 * k << "\n";
    return d.string();
  }
};

TEST_F(CompareCli, DrawsTwoRunsInOnePngAndNeverOverwrites) {
  const std::string a = fake_run("node", 100.0), b = fake_run("particle", 150.0), out = path("cmp.png");
  const auto r = run({"compare", a, b, "--labels", "node,particle", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, out + "\n");
  const std::string png = furrow::cli_test::read_text(out);
  ASSERT_GT(png.size(), 1000u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  const auto again = run({"compare", a, b, "--out", out});
  EXPECT_EQ(again.status, 1);
  EXPECT_NE(again.err.find("already exists"), std::string::npos) << again.err;
  EXPECT_EQ(furrow::cli_test::read_text(out), png);
}

TEST_F(CompareCli, MissingRunsBodiesAndLabelCountsAreErrors) {
  const std::string a = fake_run("node", 100.0);
  auto r = run({"compare", a, path("nowhere"), "--out", path("x.png")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("nowhere/forces.csv does not exist"), std::string::npos) << r.err;
  r = run({"compare", a, "--body", "cylinder", "--out", path("x.png")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("no body 'cylinder' (bodies: plate)"), std::string::npos) << r.err;
  r = run({"compare", a, a, "--labels", "one", "--out", path("x.png")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--labels: 1 labels for 2 runs"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("x.png")));
}

}  // namespace
