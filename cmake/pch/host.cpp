// The target that compiles a precompiled header (mannequin_pch_<kind>, cmake/MannequinHelpers.cmake); the
// harness targets reuse it. It is never run.
int main() { return 0; }
