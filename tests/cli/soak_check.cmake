# A short soak (brickworld soak --json): every grid index stays canonical, no body ends inside
# solid, the edits asked for are made and, outside sanitizer builds (whose allocators keep
# freed memory in quarantine), resident memory stays within 5% of its level after warm-up.
execute_process(COMMAND ${BRICKWORLD} soak --edits ${EDITS} --samples 5 --threads 2 --json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
string(JSON canonical GET "${out}" canonical)
string(JSON inside GET "${out}" bodies_inside_solid)
string(JSON edits GET "${out}" edits)
string(JSON growth GET "${out}" resident_growth)
message(STATUS "soak: ${edits} edits, canonical ${canonical}, inside solid ${inside}, resident growth ${growth}")
if(NOT canonical STREQUAL "ON" AND NOT canonical STREQUAL "true")
  message(FATAL_ERROR "soak: a grid index is not canonical (${out})")
endif()
if(NOT inside EQUAL 0)
  message(FATAL_ERROR "soak: ${inside} bodies inside solid at the end")
endif()
if(edits LESS EDITS)
  message(FATAL_ERROR "soak: ${edits} edits made, ${EDITS} asked for")
endif()
if(NOT SANITIZED AND NOT rc EQUAL 0)
  message(FATAL_ERROR "soak failed (exit ${rc}): resident growth ${growth} (limit 0.05)\n${err}")
endif()
