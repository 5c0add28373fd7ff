// jsatlas: learn neural surface atlases (Deprelle et al., NeurIPS 2022).
#include <iostream>

#include "bin/commands.h"
#include "engine/check.h"

int main(int argc, char** argv) {
  CLI::App app{
      "jsatlas: learn joint surface atlases of meshes and point clouds\n"
      "(Deprelle, Groueix, Aigerman, Kim, Aubry: Learning Joint Surface Atlases, NeurIPS 2022)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "jsatlas 0.1.0");
  jsa::cli::add_fit(app);
  jsa::cli::add_mesh(app);
  jsa::cli::add_chart(app);
  jsa::cli::add_show(app);
  jsa::cli::add_correspond(app);
  jsa::cli::add_eval(app);
  jsa::cli::add_eval_corr(app);
  // CLI11 would call an unknown word "extra arguments"; name it instead.
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    std::string names;
    for (const CLI::App* sub : app.get_subcommands({})) {
      known = known || sub->get_name() == argv[1];
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "jsatlas: unknown command '" << argv[1] << "' (commands: " << names
                << "; see --help)\n";
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "jsatlas: " << e.what() << " (see --help)\n";
    return 2;
  } catch (const jsa::cli::ExitCode& e) {
    return e.code;
  } catch (const jsa::InputError& e) {
    std::cerr << "jsatlas: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "jsatlas: error: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "jsatlas: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
