// specdeform: spectral mesh deformation from the command line.
//
// Exit codes: 0 success, 1 bad input (file, scene), 2 bad arguments, 3 numerical failure.
#include <iostream>
#include <new>

#include <CLI/CLI.hpp>

#include "common.h"
#include "specdeform/exceptions.h"

int main(int argc, char** argv) {
  CLI::App app{"specdeform: detail-preserving spectral deformation of triangle meshes",
               "specdeform"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "specdeform 0.1.0");
  specdeform::cli::add_info_command(app);
  specdeform::cli::add_basis_command(app);
  specdeform::cli::add_smooth_command(app);
  specdeform::cli::add_generate_command(app);
  specdeform::cli::add_subdivide_command(app);
  specdeform::cli::add_deform_command(app);
  specdeform::cli::add_bench_command(app);
  specdeform::cli::add_converge_command(app);
  specdeform::cli::add_compare_command(app);
  specdeform::cli::add_demo_command(app);
  specdeform::cli::add_edit_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string command = "specdeform";
    for (const CLI::App* sub : app.get_subcommands()) command += " " + sub->get_name();
    std::cerr << "specdeform: error: " << e.what() << " (see '" << command << " --help')\n";
    return 2;
  } catch (const specdeform::InputError& e) {
    std::cerr << "specdeform: error: " << e.what() << "\n";
    return 1;
  } catch (const specdeform::Error& e) {
    std::cerr << "specdeform: numerical failure: " << e.what() << "\n";
    return 3;
  } catch (const std::bad_alloc&) {
    std::cerr << "specdeform: error: out of memory\n";
    return 3;
  }
  return 0;
}
