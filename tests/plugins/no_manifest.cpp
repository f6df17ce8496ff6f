// A shared library that is not an ssx plugin.
extern "C" __attribute__((visibility("default"))) int some_function(int x) { return x + 1; }
