// Exception hierarchy of the specdeform library.
//
// Every error the library raises derives from specdeform::Error (itself a std::runtime_error),
// so callers can catch the whole family at once. The command-line program maps the two families
// below to exit codes: InputError (the user's file, scene or arguments are wrong) -> 1,
// everything else (a numerical failure) -> 3. Messages are one line and name the offending
// file or quantity.
#pragma once

#include <stdexcept>
#include <string>

namespace specdeform {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bad input: unreadable or malformed files, meshes the algorithms cannot work on, bad scenes,
// arguments out of range.
class InputError : public Error {
 public:
  using Error::Error;
};

// A numerical method failed: a factorization broke down or an iteration did not converge.
class SolverError : public Error {
 public:
  using Error::Error;
};

}  // namespace specdeform
