// mpm-prep: scene file to model stream.
//   mpm-prep examples/taylor-bar/scene.toml -o taylor.model
//   mpm-prep scene.toml --set grid.cell_size="0.38 mm" | mpm-run | mpm-post taylor -
#include <CLI/CLI.hpp>
#include <cstdio>

#include "mpm/core/cli.hpp"
#include "mpm/core/error.hpp"
#include "mpm/core/version.hpp"
#include "mpm/prep/prep.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "mpm-prep: turn a scene (TOML, see docs/scene.md) into a model stream of\n"
      "particles for mpm-run. Prints a summary on stderr. Exit status: 0 done,\n"
      "2 bad input, 4 write failure.",
      "mpm-prep"};
  mpm::PrepOptions opt;
  app.add_option("scene", opt.scene, "scene file, - for stdin")->required();
  app.add_option("-o,--output", opt.output, "model stream, - for stdout")->capture_default_str();
  app.add_option("--set", opt.overrides,
                 "override a scene value, KEY=VALUE (e.g. grid.cell_size=0.38mm); repeatable")
      ->allow_extra_args(false);
  app.add_flag("-q,--quiet", opt.quiet, "no summary on stderr");
  std::string max_memory;
  app.add_option("--max-memory", max_memory,
                 "refuse a model that would need more memory (e.g. 16G; K, M, G, T are powers "
                 "of 1024); default: the machine's memory");
  app.set_version_flag("--version", std::string("mpm-prep ") + mpm::kVersion);
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
  return mpm::guarded_main("mpm-prep", [&] {
    mpm::ignore_sigpipe();
    mpm::refuse_terminal_output(opt.output, "the model stream");
    mpm::check_output_file(opt.output, {opt.scene});
    if (!max_memory.empty()) opt.max_memory = mpm::parse_memory_size(max_memory, "--max-memory");
    return mpm::prepare_model(opt);
  });
}
