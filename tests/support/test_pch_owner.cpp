// The owner of the test programs' shared precompiled header (tests/CMakeLists.txt): a program
// with no tests of its own, linked with gtest_main like the others.
