// The translation unit fovea_test_pch and fovea_grpc_test_pch are built
// from: their precompiled headers (CMakeLists.txt) are what the tests
// reuse; this file itself holds nothing.
