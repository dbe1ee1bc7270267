#pragma once
// What every fuzz target shares: a check that stops the run (libFuzzer keeps
// the input as a crash) when a property of the code under test is broken.
#include <cstdio>
#include <cstdlib>

// Not assert(): the check must hold in every build type.
#define FUZZ_CHECK(cond)                                                                 \
  do {                                                                                   \
    if (!(cond)) {                                                                       \
      std::fprintf(stderr, "%s:%d: fuzz check failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                      \
    }                                                                                    \
  } while (false)
