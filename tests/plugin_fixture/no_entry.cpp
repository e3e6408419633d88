// A shared library that is not a vdyn plugin (no entry points).
extern "C" int fixture_something_else() { return 42; }
