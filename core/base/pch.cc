// The translation unit fovea_core_pch is built from: its precompiled
// headers (core/CMakeLists.txt) are what the core libraries reuse; this
// file itself holds nothing.
