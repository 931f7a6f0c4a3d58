// furrow: command-line front end. Wires commands together; holds no physics and no drawing code.
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "app/cli.hpp"
#include "app/drivers.hpp"
#include "app/mpi_sweep.hpp"
#include "app/run_movies.hpp"
#include "engine/simulation.hpp"
#include "render/plot.hpp"

using namespace furrow;

static void print_main_help() {
  std::cout << "furrow " << FURROW_VERSION
            << " - granular intrusion studio (2D plane-strain MPM, NDPM/DPM)\n\n"
               "usage: furrow COMMAND [options]\n       furrow COMMAND --help\n\ncommands:\n";
  for (const auto& c : cli::commands()) {
    std::string n = c.name;
    n.resize(12, ' ');
    std::cout << "  " << n << c.summary << "\n";
  }
  std::cout << "\n  --help       show this help\n  --version    print the version\n";
}

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    print_main_help();
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "--version") {
    std::cout << "furrow " << FURROW_VERSION << "\nMPI: " << cli::mpi::build_text()
              << "\nparticle state: "
              << (FURROW_FLOAT_STATE ? "float stress, pressure, mass, affine matrix, strain rate (FURROW_FLOAT_STATE=ON)"
                                     : "double (FURROW_FLOAT_STATE=OFF)")
              << "\ninstruction set: " << furrow::instruction_set() << "\n";
    return 0;
  }
  // sweep and study live in the app core (shared with the Python module); the CLI draws for them
  auto& hooks = cli::cli_driver_hooks();
  hooks.write_figure_png = [](const render::PlotFigure& f, const std::string& path) {
    render::write_figure_png(f, path, true);
  };
  hooks.render_movies = [](const std::string& dir, const Scene& s) { cli::render_run_movies(dir, s, true); };
  const cli::Command* cmd = nullptr;
  for (const auto& c : cli::commands())
    if (c.name == args[0]) cmd = &c;
  if (!cmd) {
    std::cerr << "furrow: unknown command '" << args[0] << "' (see 'furrow --help')\n";
    return 2;
  }
  std::vector<std::string> rest(args.begin() + 1, args.end());
  for (const auto& a : rest)
    if (a == "--help" || a == "-h") {
      std::cout << cli::help_text(*cmd);
      return 0;
    }
  try {
    cli::Parsed p = cli::parse(*cmd, rest);
    return cmd->main(p);
  } catch (const cli::UsageError& e) {
    std::cerr << "furrow " << cmd->name << ": " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "furrow " << cmd->name << ": error: " << e.what() << "\n";
    return 1;
  }
}
