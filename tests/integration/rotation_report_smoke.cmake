# Smoke test of `haarcast rotation-report` (run by ctest as rotation_report_smoke):
#   cmake -DHAARCAST=<path to haarcast> -P rotation_report_smoke.cmake
# 1. A small report must run, print one JSON document on stdout with every
#    method and every measurement, and spatial must match itself exactly.
# 2. A bad level must be refused with a non-zero exit and a message naming it.
cmake_minimum_required(VERSION 3.19)  # string(JSON ...)

if(NOT DEFINED HAARCAST OR NOT EXISTS "${HAARCAST}")
  message(FATAL_ERROR "pass -DHAARCAST=<path to the haarcast binary> (got '${HAARCAST}')")
endif()

# ---- 1. a valid report ------------------------------------------------------
set(cmd "${HAARCAST}" rotation-report --level 4 --rotations 8 --json)
list(JOIN cmd " " cmd_text)
execute_process(COMMAND ${cmd}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
if(NOT rc STREQUAL "0")
  message(FATAL_ERROR "`${cmd_text}` failed (${rc})\nstdout:\n${out}\nstderr:\n${err}")
endif()

string(JSON root_type ERROR_VARIABLE json_err TYPE "${out}")
if(json_err OR NOT root_type STREQUAL "OBJECT")
  message(FATAL_ERROR "stdout of `${cmd_text}` is not a JSON object: ${json_err}\nstdout:\n${out}")
endif()

# get(<var> <path...>): the value at path, or a fatal error naming the path.
macro(get var)
  string(JSON ${var} ERROR_VARIABLE get_err GET "${out}" ${ARGN})
  if(get_err)
    string(REPLACE ";" "." get_path "${ARGN}")
    message(FATAL_ERROR "report lacks ${get_path}: ${get_err}\nstdout:\n${out}")
  endif()
  string(JSON ${var}_type TYPE "${out}" ${ARGN})
endmacro()

get(level level)
if(NOT level_type STREQUAL "NUMBER" OR NOT level EQUAL 4)
  message(FATAL_ERROR "report says level = ${level} (${level_type}), expected 4")
endif()

# A PSNR is a number, or the string "inf" when the error is exactly zero
# (JSON has no infinity).
foreach(method haar spatial matrix table)
  foreach(key psnr_map_vs_exact psnr_render_vs_exact psnr_render_vs_spatial)
    get(value methods ${method} ${key})
    if(NOT value_type STREQUAL "NUMBER" AND NOT (value_type STREQUAL "STRING" AND value STREQUAL "inf"))
      message(FATAL_ERROR "methods.${method}.${key} = '${value}' (${value_type}): expected a number or \"inf\"")
    endif()
  endforeach()
  foreach(key ns_per_rotation stored_bytes)
    get(value methods ${method} ${key})
    if(NOT value_type STREQUAL "NUMBER" OR NOT value GREATER 0)
      message(FATAL_ERROR "methods.${method}.${key} = '${value}' (${value_type}): expected a positive number")
    endif()
  endforeach()
endforeach()

# spatial against itself is exact: "inf", or at least a PSNR no float noise reaches.
get(self methods spatial psnr_render_vs_spatial)
if(NOT (self_type STREQUAL "STRING" AND self STREQUAL "inf") AND
   NOT (self_type STREQUAL "NUMBER" AND self GREATER 200))
  message(FATAL_ERROR "methods.spatial.psnr_render_vs_spatial = '${self}': expected \"inf\" or > 200 dB")
endif()

# ---- 2. bad input gets a clear error -----------------------------------------
set(bad "${HAARCAST}" rotation-report --level 99)
list(JOIN bad " " bad_text)
execute_process(COMMAND ${bad}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
# A crash reports a signal name instead of an exit code: that is not a clear error either.
if(NOT rc MATCHES "^[0-9]+$" OR rc EQUAL 0)
  message(FATAL_ERROR "`${bad_text}` should exit non-zero with an error, got '${rc}'\nstdout:\n${out}\nstderr:\n${err}")
endif()
string(TOLOWER "${out}${err}" message_text)
if(NOT message_text MATCHES "level")
  message(FATAL_ERROR "`${bad_text}` exited ${rc} but its message does not mention the level:\n${out}${err}")
endif()

message(STATUS "rotation-report smoke test passed")
