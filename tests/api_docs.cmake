# Runs doxygen over the public headers (docs/Doxyfile.in) and fails on any warning it gives: a
# class, function, member, enum or macro without a comment, or a comment doxygen cannot read
# (an unescaped <element>, an unknown @command, a @copydoc that names nothing).
#   cmake -DDOXYGEN=... -DDOXYFILE=... -DOUT=... -P api_docs.cmake
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${DOXYGEN} ${DOXYFILE} RESULT_VARIABLE status OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "doxygen failed (${status}): ${err}")
endif()
file(STRINGS ${OUT}/warnings.txt warnings)
list(REMOVE_DUPLICATES warnings)
list(LENGTH warnings count)
if(count GREATER 0)
  list(JOIN warnings "\n" listing)
  message(FATAL_ERROR "${count} doxygen warnings in the public headers: document every public class and member\n"
                      "${listing}")
endif()
message(STATUS "every public class and member of the headers is documented")
