// A shared library named like a plugin but without the entry point.
extern "C" int penumbra_something_else() { return 42; }
