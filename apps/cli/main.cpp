// specdeform: spectral mesh deformation from the command line.
//
// Exit codes: 0 success, 1 bad input (file, scene), 2 bad arguments, 3 numerical failure (and,
// as a last resort, any other error). Errors are one line on stderr; a command run with --json
// also prints {"error": message, "exit_code": code} on stdout.
#include <algorithm>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "common.h"
#include "huge_pages_start.h"
#include "specdeform/exceptions.h"
#include "specdeform/version.h"

namespace {

// Reports a failure: `prefix` and the message on stderr, and with the chosen command's --json flag
// the JSON object on stdout. Returns the exit code.
int fail(const CLI::App& app, int argc, char** argv, int code, const char* prefix,
         const std::string& message) {
  std::cerr << "specdeform: " << prefix << message << "\n";
  const std::vector<CLI::App*> chosen = app.get_subcommands();
  const CLI::Option* json = chosen.empty() ? nullptr : chosen.back()->get_option_no_throw("--json");
  const bool asked = json != nullptr && json->get_expected_min() == 0 &&
                     std::any_of(argv + 1, argv + argc,
                                 [](const char* a) { return std::strcmp(a, "--json") == 0; });
  if (asked) {
    const nlohmann::ordered_json j = {{"error", message}, {"exit_code", code}};
    std::cout << specdeform::cli::json_text(j) << std::endl;
  }
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  specdeform::apps::restart_with_huge_pages(argv);
  CLI::App app{"specdeform: detail-preserving spectral deformation of triangle meshes",
               "specdeform"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "specdeform " + std::string(specdeform::version()));
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
    return fail(app, argc, argv, 2,
                "error: ", std::string(e.what()) + " (see '" + command + " --help')");
  } catch (const specdeform::InputError& e) {
    return fail(app, argc, argv, 1, "error: ", e.what());
  } catch (const specdeform::Error& e) {
    return fail(app, argc, argv, 3, "numerical failure: ", e.what());
  } catch (const std::bad_alloc&) {
    return fail(app, argc, argv, 3, "error: ", "out of memory");
  } catch (const std::exception& e) {  // a bug: still one line and an exit code
    return fail(app, argc, argv, 3, "internal error: ", e.what());
  }
  return 0;
}
