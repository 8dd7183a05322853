// specdeform: spectral mesh deformation from the command line.
//
// Exit codes: 0 success, 1 bad input (file, scene), 2 bad arguments, 3 numerical failure (and,
// as a last resort, any other error). Errors are one line on stderr; a command run with --json
// also prints {"error": message, "exit_code": code} on stdout.
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "common.h"
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

// The CLI owns its process, so it has glibc's malloc ask the kernel for transparent huge pages
// on its large blocks (the tunable glibc.malloc.hugetlb=1, read only when a program starts: the
// program starts itself once more with it). Under a hypervisor the first touch of a 4 KB page
// costs about 8.5 us, and every stage's fresh arrays, CHOLMOD's factor included, paid it: the 692k
// armadillo's deform took 16.7 s without them and 9.5 s with them, the 2.77M one 100 s and 47 s,
// at the same peak memory (docs/results.md, "Huge pages for the whole program"). A
// GLIBC_TUNABLES that names the tunable (=0 to turn it off) is kept as it is; a glibc without the
// tunable ignores it, and a failed restart carries on as it is.
void restart_with_huge_pages(char** argv) {
#if defined(__GLIBC__) && defined(__linux__)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables != nullptr && std::strstr(tunables, "glibc.malloc.hugetlb") != nullptr) return;
  const std::string value = (tunables != nullptr && *tunables != '\0')
                                ? std::string(tunables) + ":glibc.malloc.hugetlb=1"
                                : std::string("glibc.malloc.hugetlb=1");
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
#else
  (void)argv;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  restart_with_huge_pages(argv);
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
