# Runs doxygen over the public headers and counts the classes and members it finds undocumented.
# Fails when there are more than the baseline (docs/api_undocumented.txt): the count may only fall.
#   cmake -DDOXYGEN=... -DDOXYFILE=... -DOUT=... -DBASELINE=... -P api_docs.cmake
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${DOXYGEN} ${DOXYFILE} RESULT_VARIABLE status OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "doxygen failed (${status}): ${err}")
endif()
file(STRINGS ${OUT}/warnings.txt undocumented REGEX "is not documented")
list(LENGTH undocumented count)
file(READ ${BASELINE} baseline)
string(STRIP "${baseline}" baseline)
if(count GREATER baseline)
  list(JOIN undocumented "\n" listing)
  message(FATAL_ERROR "${count} undocumented classes and members in the public headers, more than the ${baseline} of "
                      "docs/api_undocumented.txt: document what was added\n${listing}")
endif()
message(STATUS "${count} undocumented classes and members in the public headers (baseline ${baseline})")
