# docs/build.md trap 2 guard: Simbody's libSimTKmath exports C symbols with the same names as
# SUNDIALS 6.4, so no binary that can share a process with Simbody may export or import SUNDIALS
# symbols dynamically. Run as
#   cmake -DNM=<nm> -DFILES="<lib>;<exe>;..." -P symbol_guard.cmake
# Fails if `nm -D` of any file lists a line matching ' [UTWDB] (N_V|SUN|ERKStep|ARKode|ARKStep|CVode|IDA)'.
# Each file must also be readable by nm and, for the integrators library, export redmax's own
# symbols, so the check cannot pass vacuously.
if(NOT NM)
  set(NM nm)
endif()
if(NOT FILES)
  message(FATAL_ERROR "symbol_guard: no FILES given")
endif()
set(_bad "")
foreach(f IN LISTS FILES)
  if(NOT EXISTS "${f}")
    message(FATAL_ERROR "symbol_guard: ${f} does not exist (build it first)")
  endif()
  execute_process(COMMAND "${NM}" -D "${f}" OUTPUT_VARIABLE _out ERROR_VARIABLE _err
                  RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "symbol_guard: '${NM} -D ${f}' failed (${_rc}): ${_err}")
  endif()
  if(f MATCHES "redmax_integrators" AND NOT _out MATCHES "makeIntegrator")
    message(FATAL_ERROR "symbol_guard: ${f} does not export makeIntegrator; is it the right file?")
  endif()
  string(REPLACE "\n" ";" _lines "${_out}")
  set(_n 0)
  foreach(line IN LISTS _lines)
    if(line MATCHES " [UTWDB] (N_V|SUN|ERKStep|ARKode|ARKStep|CVode|IDA)")
      math(EXPR _n "${_n} + 1")
      if(_n LESS_EQUAL 5)
        string(APPEND _bad "  ${f}: ${line}\n")
      endif()
    endif()
  endforeach()
  if(_n GREATER 5)
    string(APPEND _bad "  ${f}: ... ${_n} such symbols in all\n")
  endif()
  message(STATUS "symbol_guard: ${f}: ${_n} SUNDIALS symbols in the dynamic table")
endforeach()
if(_bad)
  message(FATAL_ERROR "symbol_guard: SUNDIALS symbols visible in the dynamic symbol table "
                      "(they would clash with Simbody's bundled CPodes, docs/build.md trap 2):\n${_bad}")
endif()
