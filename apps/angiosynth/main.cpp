// angiosynth: the command line. Thin: parse, call src/, report.
#include <CLI/CLI.hpp>

#include <iostream>

#include "angiosynth/version.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "core/interrupt_cleanup.hpp"
#include "degrade/effect.hpp"
#include "grow/method.hpp"

int main(int argc, char** argv) {
  using namespace angiosynth;
  installInterruptCleanup();  // before any thread starts, so every thread leaves the signals to it
  CLI::App app{"angiosynth: synthetic vascular trees and angiography volumes with exact ground truth"};
  app.set_version_flag("--version", std::string("angiosynth ") + kVersion);
  app.require_subcommand(1);
  cli::GenerateArgs gen;
  cli::VascuSynthArgs vs;
  auto* g = cli::addGenerate(app, gen);
  auto* v = cli::addVascuSynth(app, vs);
  cli::DatasetArgs ds;
  auto* d = cli::addDataset(app, ds);
  auto* fx = app.add_subcommand("effects", "list the degradation effects and their parameters (Markdown)");
  auto* gm = app.add_subcommand("methods", "list the growth methods and their parameters (Markdown)");
  cli::ParamsArgs pa;
  auto* pm = cli::addParams(app, pa);
  cli::InitArgs ia;
  auto* in = cli::addInit(app, ia);
  cli::ScoreArgs sa;
  auto* sc = cli::addScore(app, sa);
  cli::SegmentArgs sg;
  auto* se = cli::addSegment(app, sg);
  cli::BenchmarkArgs ba;
  auto* bm = cli::addBenchmark(app, ba);
  cli::StatsArgs st;
  auto* stt = cli::addStats(app, st);
  cli::MeshArgs ma;
  auto* me = cli::addMesh(app, ma);
  cli::RasterizeArgs ra;
  auto* ras = cli::addRasterize(app, ra);
  cli::PlotCalibreArgs pc;
  auto* pl = cli::addPlotCalibre(app, pc);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help, version or the error
    return code == 0 ? 0 : 2;      // a usage error is bad input: exit 2, as for files
  }
  const std::string cmdline = cli::commandLine(argc, argv);
  try {
    if (g->parsed()) return cli::runGenerate(gen, cmdline);
    if (v->parsed()) return cli::runVascuSynth(vs, cmdline);
    if (d->parsed()) return cli::runDatasetCommand(ds, cmdline);
    if (pm->parsed()) return cli::runParams(pa);
    if (in->parsed()) return cli::runInit(ia);
    if (sc->parsed()) return cli::runScore(sa);
    if (pl->parsed()) return cli::runPlotCalibre(pc);
    if (se->parsed()) return cli::runSegment(sg);
    if (me->parsed()) return cli::runMesh(ma, cmdline);
    if (ras->parsed()) return cli::runRasterize(ra, cmdline);
    if (bm->parsed()) return cli::runBenchmarkCommand(ba, cmdline);
    if (stt->parsed()) return cli::runStats(st);
    if (fx->parsed()) {
      std::cout << effectReference();
      return 0;
    }
    if (gm->parsed()) {
      std::cout << methodReference();
      return 0;
    }
  } catch (const InputError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "angiosynth: internal error: " << e.what() << "\n";
    return 3;
  }
  return 1;
}
