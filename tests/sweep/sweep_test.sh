#!/usr/bin/env bash
# ssx sweep, end to end: checks before any run, the same rows on 1 and 2 processes and under
# mpirun, failed runs recorded, resume after a kill, a results file of another sweep refused.
#   sweep_test.sh SSX TEST_PLUGIN_DIR WORK_DIR EXPECT_MPI(ON|OFF)
set -euo pipefail
ssx=$1 plugins=$2 work=$3 expect_mpi=$4
here=$(cd "$(dirname "$0")" && pwd)
data=$here/../data/sweeps
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
rows() { tail -n +3 "$1" | sort -t, -k1,1n; }  # the runs' rows, by run index
# refused SWEEP OUT LOG: ssx sweep must refuse SWEEP (exit status 2) writing to OUT; what it said goes to LOG
refused() {
  local status=0
  "$ssx" sweep "$1" --plugin-path "$plugins" --out "$2" > "$3" 2>&1 || status=$?
  cat "$3"
  [ "$status" -eq 2 ] || fail "ssx sweep $1 exited with $status, expected 2"
}

# --- a broken sweep: every problem with file:line, nothing written ---
cat > broken.xml <<'XML'
<sweep scene="SCENE" seeds="0">
  <grid>
    <parameter name="gain" target="swarm/driver@formation_gain" values="0.1 -1"/>
    <parameter name="g2" target="swarm/driver@formation_gian" values="1"/>
    <parameter name="nope" target="swarm[7]/driver@x" values="1"/>
  </grid>
  <metrics><plugin name="no_such_metric"/></metrics>
</sweep>
XML
sed -i "s|SCENE|$data/scene.xml|" broken.xml
refused broken.xml broken.csv broken.out
grep -q "broken.xml:1: error: <sweep>: attribute 'seeds' must be a whole number in \[1, 1000000\], got '0'" broken.out || fail "seeds"
[ ! -e broken.csv ] || fail "a broken sweep created its output"
sed -i 's/seeds="0"/seeds="1"/' broken.xml
refused broken.xml broken.csv broken.out
grep -q "broken.xml:3: error: <driver>: driver 'quadrotor': parameter 'formation_gain' must be > 0" broken.out || fail "value check"
grep -q "broken.xml:4: error: unknown parameter 'formation_gian' of driver 'quadrotor'" broken.out || fail "unknown attribute"
grep -q "broken.xml:5: error: target 'swarm\[7\]/driver@x': no element 'swarm\[7\]'" broken.out || fail "bad target"
[ ! -e broken.csv ] || fail "a broken sweep created its output"
# the metric is checked once the values are right
sed -i 's/values="0.1 -1"/values="0.1"/; /formation_gian/d; /swarm\[7\]/d' broken.xml
refused broken.xml broken.csv broken.out
grep -q "broken.xml:5: error: metric 'no_such_metric': no plugin of this scene publishes it (published: formation_error, tracking_error)" broken.out \
  || fail "unknown metric"

# one attribute targeted twice (however spelled) and a metric column that every row has are refused
cat > twice.xml <<'XML'
<sweep scene="SCENE">
  <grid>
    <parameter name="g1" target="swarm/driver@formation_gain" values="0.1 0.2"/>
    <parameter name="g2" target="swarm[name=q{i}]/driver@formation_gain" values="0.3"/>
  </grid>
  <metrics><settle_time of="tracking_error" below="0.5" column="run"/></metrics>
</sweep>
XML
sed -i "s|SCENE|$data/scene.xml|" twice.xml
refused twice.xml twice.csv twice.out
grep -q "twice.xml:6: error: <metrics>: column 'run' would appear twice in the results (every row has it)" twice.out \
  || fail "reserved column"
sed -i 's/column="run"/column="settled"/' twice.xml
refused twice.xml twice.csv twice.out
grep -q "twice.xml:4: error: target 'swarm\[name=q{i}\]/driver@formation_gain' sets the attribute that target 'swarm/driver@formation_gain' (.*twice.xml:3) sets" twice.out \
  || fail "one attribute twice"
[ ! -e twice.csv ] || fail "a refused sweep created its output"

# --- the example sweep passes its checks ---
"$ssx" sweep "$here/../../examples/sweeps/formation_gains.xml" --check | grep -q "5 point(s) x 10 seed(s) = 50 runs" \
  || fail "the example sweep"
"$ssx" sweep "$here/../../examples/sweeps/realistic_guesses.xml" --check | grep -q "27 point(s) x 1 seed(s) = 27 runs" \
  || fail "the realistic guesses sweep"

# --- no output over an input: the scene (copied here, named by --robots) is left as it was ---
cp "$data/small.xml" own.xml
sed -i "s|scene=\"\([^/\"]*\)\"|scene=\"$data/\\1\"|" own.xml
scene_file=$(sed -n 's/.*scene="\([^"]*\)".*/\1/p' own.xml | head -1)
cp "$scene_file" own_scene_copy.xml
status=0
"$ssx" sweep own.xml --plugin-path "$plugins" --out own.csv --robots "$scene_file" > own.out 2>&1 || status=$?
cat own.out
[ "$status" -eq 2 ] || fail "--robots naming the scene: exit $status, expected 2"
grep -q "which this run reads" own.out || fail "--robots naming the scene: no reason given"
cmp -s "$scene_file" own_scene_copy.xml || fail "--robots naming the scene changed the scene"
[ ! -e own.csv ] || fail "a refused sweep created its output"

# --- one process, two processes: the same rows ---
"$ssx" sweep "$data/small.xml" --plugin-path "$plugins" --out one.csv --robots one_robots.csv --jobs 1
"$ssx" sweep "$data/small.xml" --plugin-path "$plugins" --out two.csv --jobs 2
[ "$(rows one.csv | wc -l)" -eq 12 ] || fail "12 runs expected"
diff <(rows one.csv) <(rows two.csv) || fail "--jobs 1 and --jobs 2 differ"
# the failing runs are rows with their message, the others complete
[ "$(rows one.csv | grep -c ',failed,.*exploded as asked')" -eq 6 ] || fail "6 failed rows expected"
[ "$(rows one.csv | grep -c ',ok,')" -eq 6 ] || fail "6 ok rows expected"
rows one.csv | grep ',box,' | grep -q ',ok,' && fail "a run whose bomb names the box succeeded"
# per robot: 5 robots (4 quadrotors and the box) per run that finished
[ "$(tail -n +2 one_robots.csv | wc -l)" -eq 30 ] || fail "per-robot rows"
# the summary: one line per point, runs ok failed
[ "$(wc -l < one.summary.csv)" -eq 7 ] || fail "summary lines"
grep -q '^1,0.1,box,2,0,2,' one.summary.csv || fail "summary of point 1"
# the seeds differ between runs, the runs of one point differ
[ "$(rows one.csv | cut -d, -f3 | sort -u | wc -l)" -eq 12 ] || fail "run seeds"

# --- a run that takes its process down is a row too, and the sweep goes on ---
cat > crash.xml <<XML
<sweep scene="$data/scene.xml" seeds="2">
  <list>
    <parameter name="how" target="artifact[name=box]/driver@how" values="abort throw"/>
    <parameter name="only" target="artifact[name=box]/driver@only" values="box nobody"/>
  </list>
  <metrics><min_distance/></metrics>
</sweep>
XML
"$ssx" sweep crash.xml --plugin-path "$plugins" --out crash.csv --jobs 1
[ "$(rows crash.csv | grep -c ',crashed,.*signal 6')" -eq 2 ] || { cat crash.csv; fail "2 crashed rows expected"; }
[ "$(rows crash.csv | grep -c ',ok,')" -eq 2 ] || { cat crash.csv; fail "2 ok rows after the crashes expected"; }

# --- resume: a file cut short after 5 rows and half a row ---
{ head -n 7 one.csv; tail -n 1 one.csv | head -c 20; } > resumed.csv
"$ssx" sweep "$data/small.xml" --plugin-path "$plugins" --out resumed.csv --jobs 2 > resumed.out
cat resumed.out
grep -q "resuming: 5 of 12 runs are in resumed.csv" resumed.out || fail "resume message"
grep -q "ssx sweep: 7 run(s)" resumed.out || fail "resume ran 7"
diff <(rows one.csv) <(rows resumed.csv) || fail "resumed rows differ"
"$ssx" sweep "$data/small.xml" --plugin-path "$plugins" --out resumed.csv | grep -q "nothing to do" || fail "all done"
# a blank line in the results (an editor's) is no row; a line that is no row is refused, naming it
{ head -n 4 one.csv; echo; tail -n +5 one.csv; } > blank.csv
"$ssx" sweep "$data/small.xml" --plugin-path "$plugins" --out blank.csv | grep -q "nothing to do" || fail "blank line"
{ head -n 4 one.csv; echo "x,1,2"; } > edited.csv
refused "$data/small.xml" edited.csv edited.out
grep -q "'edited.csv' line 5 is no row of this sweep (its first field 'x' is no run number)" edited.out || fail "edited row"
# another sweep's results file is refused and left alone
sed 's/seed="5"/seed="6"/' "$data/small.xml" > other.xml
sed -i "s|scene=\"scene.xml\"|scene=\"$data/scene.xml\"|" other.xml
cp resumed.csv before.csv
refused other.xml resumed.csv other.out
grep -q "holds the results of another sweep" other.out || fail "another sweep's file"
cmp -s before.csv resumed.csv || fail "another sweep's file was changed"

# --- under mpirun: rank 0 hands out runs, the same rows ---
if [ "$expect_mpi" = ON ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
  mpirun --oversubscribe -np 3 "$ssx" sweep "$data/small.xml" --plugin-path "$plugins" --out mpi.csv
  diff <(rows one.csv) <(rows mpi.csv) || fail "mpirun -np 3 differs from --jobs 1"
else
  echo "ssx was built without MPI: the mpirun part is skipped"
fi
echo "sweep tests passed"
