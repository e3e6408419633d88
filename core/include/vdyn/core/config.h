#pragma once
// Build guard for every vdyn translation unit that includes Simbody.
//
// Debian's Simbody 3.7 library was compiled without NDEBUG. Simbody's headers
// change inline code and class layouts under NDEBUG, so a file compiled with
// -DNDEBUG (CMake's Release default) links but crashes at run time. The project's
// CMakeLists compiles with -UNDEBUG; this makes any other build fail here.
#ifdef NDEBUG
#error "vdyn must be compiled without NDEBUG (Debian's Simbody was built without it; mixing crashes at run time). Use the project's CMakeLists, which passes -UNDEBUG."
#endif
#if __cplusplus > 201703L
#error "vdyn is C++17: Simbody 3.7's headers do not compile as C++20 (ambiguous operator== on SimTK index types)."
#endif
