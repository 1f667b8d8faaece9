# Sanitizers and fuzzing (docs/fuzzing.md). Included once, at the end of CMakeLists.txt,
# after fdem_core is defined: the flags go on fdem_core as PUBLIC options, so fdem,
# fdem_tests and the fuzz targets that link it are built the same way.
#
#   -DFDEM_SANITIZE=ON  AddressSanitizer + UndefinedBehaviorSanitizer (measured with clang), and
#                       fdem_fast_tests: the reader, case and CLI suites only (what CI runs
#                       under the sanitizers; the physics suites are too slow there).
#   -DFDEM_FUZZ=ON      libFuzzer targets of tests/fuzz, one per reader (clang only; Debian
#                       packages clang and libclang-rt-14-dev). Implies FDEM_SANITIZE.
#                       Target fuzz_corpus writes the seed corpora under
#                       ${CMAKE_BINARY_DIR}/fuzz/corpus from committed files.
option(FDEM_SANITIZE "Build with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(FDEM_FUZZ "Build the libFuzzer targets of tests/fuzz (clang)" OFF)

if(FDEM_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "FDEM_FUZZ needs clang (libFuzzer): CC=clang CXX=clang++ cmake -DFDEM_FUZZ=ON ...")
  endif()
  set(FDEM_SANITIZE ON)
endif()

if(FDEM_SANITIZE)
  # No recovery: the first report ends the process with a non-zero status, so a test or
  # a fuzz run cannot pass over one. -O1 keeps the stack traces readable.
  set(FDEM_SANITIZE_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer -g -O1)
  target_compile_options(fdem_core PUBLIC ${FDEM_SANITIZE_FLAGS})
  target_link_options(fdem_core PUBLIC -fsanitize=address,undefined)
  if(FDEM_FUZZ)
    # Coverage feedback for libFuzzer in the library under test; the runtime comes with
    # -fsanitize=fuzzer on each fuzz target.
    target_compile_options(fdem_core PUBLIC -fsanitize=fuzzer-no-link)
  endif()

  # The fast suites under the sanitizers: the same test sources as fdem_tests for the
  # readers, the case file and the CLI, without the long physics suites.
  file(GLOB FDEM_FAST_TEST_SOURCES CONFIGURE_DEPENDS
       ${CMAKE_SOURCE_DIR}/tests/test_case_*.cpp ${CMAKE_SOURCE_DIR}/tests/test_gmsh*.cpp
       ${CMAKE_SOURCE_DIR}/tests/test_mesh_refine.cpp ${CMAKE_SOURCE_DIR}/tests/test_cli*.cpp)
  add_executable(fdem_fast_tests tests/main.cpp ${FDEM_FAST_TEST_SOURCES})
  target_include_directories(fdem_fast_tests PRIVATE ${DOCTEST_INCLUDE_DIR} ${CMAKE_SOURCE_DIR}/tests)
  target_compile_definitions(fdem_fast_tests PRIVATE
    FDEM_SOURCE_DIR="${CMAKE_SOURCE_DIR}" FDEM_BINARY="$<TARGET_FILE:fdem>")
  target_link_libraries(fdem_fast_tests PRIVATE fdem_core)
  add_dependencies(fdem_fast_tests fdem)
  # Leak checks included: the CLI tests run fdem on PoCL, which exits without leaks (no
  # suppressions needed on Debian 12).
  add_test(NAME sanitize COMMAND fdem_fast_tests --test-suite=gmsh,case,cli --no-intro=true)
  set_tests_properties(sanitize PROPERTIES LABELS "sanitize" TIMEOUT 900 ENVIRONMENT
    "ASAN_OPTIONS=detect_leaks=1;UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1")
endif()

if(FDEM_FUZZ)
  set(FDEM_FUZZ_TARGETS fuzz_case fuzz_msh fuzz_geo fuzz_checkpoint)
  foreach(target ${FDEM_FUZZ_TARGETS})
    add_executable(${target} tests/fuzz/${target}.cpp)
    target_include_directories(${target} PRIVATE ${CMAKE_SOURCE_DIR}/tests/fuzz)
    target_compile_definitions(${target} PRIVATE FDEM_SOURCE_DIR="${CMAKE_SOURCE_DIR}")
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer)
    target_link_options(${target} PRIVATE -fsanitize=fuzzer)
    target_link_libraries(${target} PRIVATE fdem_core)
  endforeach()
  # Writes synthetic checkpoints through the project's own writer (seeds for
  # fuzz_checkpoint: a checkpoint that passes its checksum, so the fuzzer starts past it).
  add_executable(fuzz_checkpoint_seeds tests/fuzz/checkpoint_seeds.cpp)
  target_link_libraries(fuzz_checkpoint_seeds PRIVATE fdem_core)
  add_custom_target(fuzz_corpus
    COMMAND bash ${CMAKE_SOURCE_DIR}/tests/fuzz/make_corpus.sh ${CMAKE_SOURCE_DIR} ${CMAKE_BINARY_DIR}/fuzz/corpus
            $<TARGET_FILE:fuzz_checkpoint_seeds>
    DEPENDS fuzz_checkpoint_seeds
    COMMENT "Seed corpora for the fuzz targets (tests/fuzz/make_corpus.sh)"
    VERBATIM)
  add_custom_target(fuzz_all DEPENDS ${FDEM_FUZZ_TARGETS} fuzz_corpus)
  # A short run of each target from its seeds, and the recorded crashes replayed (label
  # "fuzz"; tests/fuzz/run.sh).
  foreach(target ${FDEM_FUZZ_TARGETS})
    add_test(NAME ${target} COMMAND bash ${CMAKE_SOURCE_DIR}/tests/fuzz/run.sh $<TARGET_FILE:${target}>
             ${CMAKE_BINARY_DIR}/fuzz/corpus ${CMAKE_SOURCE_DIR}/tests/fuzz/regressions)
    set_tests_properties(${target} PROPERTIES LABELS "fuzz" TIMEOUT 300)
  endforeach()
endif()
