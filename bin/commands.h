// Each subcommand registers itself on the CLI11 app; main() only dispatches and
// turns every error into one line on stderr and a non-zero exit code.
#pragma once
#include <CLI/CLI.hpp>

namespace jsa::cli {

// Thrown by a command that must end with a specific exit code (e.g. 130 after
// Ctrl-C, once the checkpoint is safe).
struct ExitCode {
  int code;
};

void add_fit(CLI::App& app);
void add_eval(CLI::App& app);
void add_mesh(CLI::App& app);
void add_chart(CLI::App& app);
void add_correspond(CLI::App& app);
void add_eval_corr(CLI::App& app);
void add_show(CLI::App& app);
void add_view(CLI::App& app);

}  // namespace jsa::cli
