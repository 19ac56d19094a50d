// SPDX-License-Identifier: Apache-2.0
// OpenVDB's failed internal assertions as exceptions, while vdbpack is
// inside one of its guarded OpenVDB calls (vpv::guard).
//
// Debian's libopenvdb is built with assertions on: some corrupt files (a
// points grid whose paged attribute claims more bytes than its page holds)
// reach an assert() in OpenVDB's reader, which would abort the process.
// This definition interposes glibc's __assert_fail for the whole process:
// inside a guarded call it throws, the guard maps the exception to one error
// line ("the file is corrupt"); anywhere else it reports and aborts exactly
// as glibc does. The shared library exports it (cmake/vdbpack.map): it
// interposes glibc's in programs linked to libvdbpack, the command-line
// tool among them; where the library is loaded later with dlopen (Python's
// ctypes), glibc's comes first, and the child process that reads every
// .vdb file first (src/api/probe.c) reports such a file as a reader crash.
// Deliberately without <assert.h> in this file: glibc
// declares __assert_fail noexcept, and this one must be able to throw.
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace vpv {
thread_local int guard_depth = 0;

struct assertion_failed : std::runtime_error {
    using std::runtime_error::runtime_error;
};
} // namespace vpv

extern "C" [[noreturn]] void __assert_fail(const char *expr, const char *file, unsigned line,
                                           const char *func)
{
    if (vpv::guard_depth > 0)
        throw vpv::assertion_failed(std::string("OpenVDB's reader rejected its data (internal "
                                                "check '") +
                                    expr + "' failed)");
    std::fprintf(stderr, "%s:%u: %s: Assertion `%s' failed.\n", file, line, func, expr);
    std::abort();
}
