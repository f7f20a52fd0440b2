# Issue 19's check as a user runs it: `brickworld run chain --frames 3600 --json` (60 s of the
# chain swinging) ends with every link still linked to the next, no body inside solid, and
# exit code 0 (run exits 4 when a scene check fails).
execute_process(COMMAND ${BRICKWORLD} run chain --frames ${FRAMES} --json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 1200)
string(JSON pass GET "${out}" checks pass)
string(JSON parted GET "${out}" checks linked ever_parted)
string(JSON inside GET "${out}" bodies_inside_solid)
string(JSON deepest GET "${out}" max_penetration_m)
message(STATUS "chain: ${FRAMES} frames, links ever parted ${parted}, inside solid ${inside}, deepest contact ${deepest} m")
if(NOT rc EQUAL 0 OR NOT parted EQUAL 0 OR NOT inside EQUAL 0)
  message(FATAL_ERROR "chain: exit ${rc}, ${parted} links parted, ${inside} bodies inside solid\n${err}")
endif()
if(deepest GREATER 0.05)
  message(FATAL_ERROR "chain: deepest contact ${deepest} m (a link sank into another)")
endif()
