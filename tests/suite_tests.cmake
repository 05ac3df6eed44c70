# Run at build time (cmake -P), after a module's test executable is linked: lists its tests
# (--gtest_list_tests) and writes a ctest file with one test per suite instead of one per test
# (a suite's long tests are one more, `<suite>.long`, so a fixture shared by a suite is built once).
# Why: every ctest test is a process of its own; each pays the start-up (0.05 s, 0.35 s under the
# sanitizers) and any fixture its suite builds in SetUpTestSuite, often more than the test takes.
# gtest still reports each test by name inside its suite's output.
# Inputs (-D): EXE, OUT (the file to write), MODULE (the label), COST, LONG (':'-separated gtest
# names or `Suite.*` patterns: labelled `long` only, which the sanitizer preset leaves out),
# SHARED (':'-separated suites that run as `<suite>.all`, added by tests/CMakeLists.txt: left out).
# Disabled tests (DISABLED_ prefix) are measurement sweeps, run by hand with the executable.
cmake_minimum_required(VERSION 3.25)
string(REPLACE ":" ";" LONG "${LONG}")
string(REPLACE ":" ";" SHARED "${SHARED}")
execute_process(COMMAND "${EXE}" --gtest_list_tests OUTPUT_VARIABLE listing RESULT_VARIABLE rc
                TIMEOUT 60)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${EXE} --gtest_list_tests failed (${rc}):\n${listing}")
endif()
string(REPLACE ";" "\\;" listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")

set(groups "")
set(suite "")
foreach(line IN LISTS lines)
  if(line MATCHES "^([^ #][^ ]*)\\.")
    set(suite "${CMAKE_MATCH_1}")
  elseif(line MATCHES "^  ([^ ]+)" AND NOT suite STREQUAL "")
    set(test "${CMAKE_MATCH_1}")
    if(suite MATCHES "^DISABLED_" OR test MATCHES "^DISABLED_" OR suite IN_LIST SHARED)
      continue()
    endif()
    set(group "${suite}")
    if("${suite}.${test}" IN_LIST LONG OR "${suite}.*" IN_LIST LONG)
      set(group "${suite}.long")
    endif()
    if(NOT group IN_LIST groups)
      list(APPEND groups "${group}")
    endif()
    list(APPEND "members_${group}" "${suite}.${test}")
  endif()
endforeach()

set(text "")
foreach(group IN LISTS groups)
  # The group's tests by name: a suite's long tests are a group of their own.
  list(JOIN "members_${group}" ":" filter)
  set(label ${MODULE})
  if(group MATCHES "\\.long$")
    set(label long)
  endif()
  string(APPEND text "add_test([=[${group}]=] [==[${EXE}]==] [==[--gtest_filter=${filter}]==])\n"
         "set_tests_properties([=[${group}]=] PROPERTIES LABELS ${label} COST ${COST})\n")
endforeach()
file(WRITE "${OUT}.tmp" "${text}")
file(RENAME "${OUT}.tmp" "${OUT}")
