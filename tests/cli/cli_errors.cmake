# Runs brickworld with bad arguments; each must fail (non-zero exit) with a message naming what
# was wrong, quickly (an unwritable output is refused before the scene is built).
function(expect_failure expected)
  execute_process(COMMAND ${BRICKWORLD} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
  if(rc EQUAL 0)
    message(FATAL_ERROR "brickworld ${ARGN}: succeeded; expected a failure saying '${expected}'")
  endif()
  string(FIND "${out}${err}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "brickworld ${ARGN}: said '${out}${err}'; expected '${expected}'")
  endif()
endfunction()

expect_failure("unknown subcommand 'frobnicate'" frobnicate)
# A city of a million bricks: refused before it is built (the run would take seconds first).
expect_failure("--trace: cannot write /nonexistent/dir/t.json" run city_rain --frames 1 --trace /nonexistent/dir/t.json)
expect_failure("--csv: cannot write /nonexistent/dir/r.csv" run city_rain --frames 1 --csv /nonexistent/dir/r.csv)
expect_failure("--csv: cannot write /nonexistent/dir/s.csv" sweep stack10 --frames 1 --csv /nonexistent/dir/s.csv)
expect_failure("--csv: cannot write /nonexistent/dir/t.csv" tradeoff stack10 --frames 1 --csv /nonexistent/dir/t.csv)
expect_failure("--csv: cannot write /nonexistent/dir/b.csv" batch-bench --csv /nonexistent/dir/b.csv)
expect_failure("expected a Brickadia save (.brs) or a MagicaVoxel model (.vox), got a '.json' file" inspect ${SCENES}/stack10.json)
# Recordings: an unwritable one refused before the run, none for a Bullet-only run, and `view`
# naming a missing or foreign file.
expect_failure("--record: cannot write /nonexistent/dir/r.bwr" run city_rain --frames 1 --record /nonexistent/dir/r.bwr)
expect_failure("--record records brickworld's run" run stack10 --frames 1 --engine bullet --record r.bwr)
expect_failure("--record-depth: Value 9 not in range 1 to 7" run city_rain --frames 1 --record r.bwr --record-depth 9)
expect_failure("recording /nonexistent/r.bwr: cannot open it" view /nonexistent/r.bwr -o r.html)
expect_failure("not a brickworld recording" view ${SCENES}/stack10.json -o r.html)
