// mpm-run: the solver. Reads a model stream (from mpm-prep), writes a result stream; alone,
// or under mpirun as one rank of a domain decomposition (the root reads and writes).
//   mpm-prep scene.toml | mpm-run --threads 2 --stats | mpm-post taylor -
//   mpm-prep scene.toml | mpirun -np 2 mpm-run --threads 1 | mpm-post taylor -
#include <CLI/CLI.hpp>
#include <cstdio>

#include "mpm/core/cli.hpp"
#include "mpm/core/comm.hpp"
#include "mpm/core/error.hpp"
#include "mpm/core/version.hpp"
#include "mpm/run/run.hpp"

int main(int argc, char** argv) {
  mpm::CommSession mpi(argc, argv);  // MPI, when started by mpirun
  const mpm::Comm& comm = mpm::Comm::world();
  CLI::App app{
      "mpm-run: explicit material point method solver.\n"
      "Reads a model stream (from mpm-prep) and writes a result stream of frames and\n"
      "histories (for mpm-post). Exit status: 0 done, 2 bad input, 3 unstable run,\n"
      "4 write failure, 5 a particle left the domain (solver.on_exit = \"stop\"),\n"
      "128+N stopped by signal N (SIGINT, SIGTERM: after a checkpoint;\n"
      "continue with --restart RESULT).\n"
      "Under mpirun (mpirun -np N mpm-run ...) the ranks share the particles by slabs;\n"
      "rank 0 reads the model and writes the stream.",
      "mpm-run"};
  mpm::RunOptions opt;
  std::string progress = "auto";
  app.add_option("input", opt.input, "model stream, - for stdin")->capture_default_str();
  app.add_option("-o,--output", opt.output, "result stream, - for stdout")->capture_default_str();
  app.add_option("-t,--threads", opt.threads, "OpenMP threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--set", opt.overrides,
                 "override a scene value, KEY=VALUE (e.g. solver.cfl=0.3); repeatable")
      ->allow_extra_args(false);
  app.add_flag("--stats", opt.stats, "print the per-kernel time table and throughput at the end");
  app.add_option("--strategy", opt.strategy,
                 "particle-to-grid scatter: colored (default; cell-ordered coloured chunks), "
                 "lr-slabs (004 4.1), array-expansion (000 4.1.1), patch (000 4.1.2)")
      ->check(CLI::IsMember({"colored", "lr-slabs", "array-expansion", "patch"}))
      ->capture_default_str();
  app.add_flag("--deterministic", opt.deterministic,
               "results bitwise independent of the thread count (the colored strategy is; this "
               "flag refuses the others)");
  app.add_option("--progress", progress, "progress on stderr: auto, bar, lines or none")
      ->check(CLI::IsMember({"auto", "bar", "lines", "none"}))
      ->capture_default_str();
  app.add_option("--restart", opt.restart,
                 "continue the result stream RESULT from its last intact checkpoint (a run "
                 "killed, cut or stopped by a signal); appends to RESULT, or writes -o")
      ->type_name("RESULT");
  std::string max_memory;
  app.add_option("--max-memory", max_memory,
                 "refuse a model whose run would need more memory (e.g. 16G; K, M, G, T are "
                 "powers of 1024); default: the machine's memory");
  app.set_version_flag("--version", std::string("mpm-run ") + mpm::kVersion);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    // "--set bodies.bar.velocity=0 0 -190 m/s" unquoted: the shell split the value.
    if (dynamic_cast<const CLI::ExtrasError*>(&e))
      std::fprintf(stderr,
                   "a --set value with spaces must be quoted for the shell: --set "
                   "'bodies.bar.velocity=0 0 -190 m/s' or --set bodies.bar.velocity=\"0 0 -190 "
                   "m/s\"\n");
    return code == 0 ? 0 : mpm::kExitBadInput;
  }
  opt.progress = progress == "bar"     ? mpm::ProgressMode::Bar
                 : progress == "lines" ? mpm::ProgressMode::Lines
                 : progress == "none"  ? mpm::ProgressMode::None
                                       : mpm::ProgressMode::Auto;
  auto body = [&] {
    mpm::ignore_sigpipe();
    if (!opt.restart.empty()) {
      if (app.count("input"))
        throw mpm::InputError("--restart", "continues a result stream; give no model stream");
      if (!app.count("--output")) opt.output = opt.restart;  // append to it
    }
    // Under mpirun a rank's standard output is mpirun's pseudo-terminal, whatever mpirun's own
    // is: the check would refuse every pipe.
    if (!comm.parallel()) mpm::refuse_terminal_output(opt.output, "the result stream");
    mpm::check_output_file(opt.output, {opt.input});
    if (!max_memory.empty()) opt.max_memory = mpm::parse_memory_size(max_memory, "--max-memory");
    return mpm::run_model(opt);
  };
  if (!comm.parallel()) return mpm::guarded_main("mpm-run", body);
  // Under mpirun. Errors in the input reach every rank alike (the root reads the model and
  // shares what it found): the root reports them. A failure of one rank alone (writing the
  // stream, an internal error) ends every rank, since the others would wait for it.
  int status;
  if (comm.root()) {
    status = mpm::guarded_main("mpm-run", body);
  } else {
    try {
      status = body();
    } catch (const mpm::InputError&) {  // the root reports the same error
      status = mpm::kExitBadInput;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "mpm-run (rank %d): internal error: %s\n", comm.rank(), e.what());
      status = mpm::kExitInternal;
    }
  }
  if (status == mpm::kExitInternal || status == mpm::kExitIo) comm.abort(status);
  return status;
}
