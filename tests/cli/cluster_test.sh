#!/usr/bin/env bash
# More than one process: `rsibr batch` (one job per rank, a failed job reported and the others run
# on) and, in a build with MPI, `mpirun -n N rsibr bake` giving the serial bytes.
# Usage: cluster_test.sh /path/to/rsibr [/path/to/mpiexec]   (no mpiexec: a build without MPI)
set -u
rsibr=$1
mpiexec=${2:-}
. "$(dirname "$0")/contract_lib.sh"
# CI runs as root; Open MPI refuses that unless told. --oversubscribe: more ranks than cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
mpi() { local n=$1; shift; "$mpiexec" -n "$n" --oversubscribe "$@"; }

check "batch --help" bash -c "'$rsibr' batch --help | grep -q 'mpirun'"
"$rsibr" pattern sun-sky "$work/sky.exr" --to latlong --size 64 --sun-intensity 1e6 >/dev/null
printf 'type: ggx\nroughness: 0.3\nfresnel: {type: schlick, f0: [0.9, 0.7, 0.4]}\n' >"$work/ggx.yaml"
printf 'type: lambert\nalbedo: [0.18, 0.18, 0.18]\n' >"$work/grey.yaml"

# A batch of 20 bakes, job 7 broken (its environment is missing); paths relative to the spec.
mkdir -p "$work/jobs"
cp "$work/sky.exr" "$work/ggx.yaml" "$work/jobs/"
make_spec() {
  echo "jobs:"
  for i in $(seq 1 20); do
    if [ "$i" = 7 ]; then
      echo "  - {name: broken, args: [bake, out$i.exr, --env, missing.exr, --brdf, ggx.yaml, --res, 8, -q]}"
    else
      echo "  - [bake, out$i.exr, --env, sky.exr, --brdf, ggx.yaml, --res, 8, --samples, 2, --seed, '$i', -q]"
    fi
  done
}
make_spec >"$work/jobs/batch.yaml"
summary_is() {  # summary_is FILE OK FAILED RANKS: the counts, job 7 the failed one, every job once
  /usr/bin/python3 - "$@" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
ok, failed, ranks = map(int, sys.argv[2:5])
jobs = j["jobs"]
assert j["ok"] == ok and j["failed"] == failed and j["ranks"] == ranks, (j["ok"], j["failed"], j["ranks"])
assert [x["index"] for x in jobs] == list(range(1, 21))
bad = [x for x in jobs if x["status"] != "ok"]
assert [x["index"] for x in bad] == [7] and "missing.exr" in bad[0]["error"] and bad[0]["exit_code"] == 2, bad
assert sorted({x["rank"] for x in jobs}) == list(range(ranks))
assert all(x["rank"] == (x["index"] - 1) % ranks for x in jobs)
PY
}
(cd "$work" && "$rsibr" batch jobs/batch.yaml --json serial.json -q 2>"$work/batch.err")
check "batch: exit 1 when a job failed" test $? -eq 1
check "batch: the failure is named" grep -q "19 of 20 jobs ok, 1 failed (first: job 7 'broken')" "$work/batch.err"
check "batch: 19 outputs, none for the broken job" bash -c "test \$(ls '$work/jobs' | grep -c '^out.*\.exr$') -eq 19 -a ! -e '$work/jobs/out7.exr'"
check "batch: the summary lists every job" summary_is "$work/serial.json" 19 1 1
check "batch: no temporaries" no_temporaries "$work/jobs"
"$rsibr" bake --env "$work/sky.exr" --brdf "$work/ggx.yaml" --res 8 --samples 2 --seed 3 -q "$work/alone3.exr"
check "batch: a job's bytes are the command's alone" cmp -s "$work/alone3.exr" "$work/jobs/out3.exr"
printf 'jobs:\n  - [bakee, x.exr]\n' >"$work/bad.yaml"
expect_error "batch: an unknown verb in the spec" "bad.yaml: batch.jobs\[0\]: 'bakee' is not a verb" batch "$work/bad.yaml"
printf 'jobs:\n  - [batch, bad.yaml]\n' >"$work/nested.yaml"
expect_error "batch: no batch inside a batch" "cannot run in a batch" batch "$work/nested.yaml"
expect_error "batch: a missing spec" "nospec.yaml" batch "$work/nospec.yaml"
expect_error "batch: summary onto the spec" "overwrite the input" batch "$work/bad.yaml" --json "$work/bad.yaml"
check "--threads 1 gives the same bytes" bash -c "'$rsibr' --threads 1 bake --env '$work/sky.exr' --brdf '$work/ggx.yaml' --res 8 --samples 2 --seed 3 -q '$work/t1.exr' && cmp -s '$work/t1.exr' '$work/alone3.exr'"

if [ -z "$mpiexec" ]; then
  # A build without MPI started by a launcher would do all the work once per rank: it refuses.
  OMPI_COMM_WORLD_SIZE=2 "$rsibr" info "$work/sky.exr" >/dev/null 2>"$work/nompi.err"
  check "without MPI: a launcher's ranks are refused" test $? -eq 2
  check "without MPI: the refusal says why" grep -q "built without MPI" "$work/nompi.err"
  finish cluster_test
  exit
fi

# mpirun bakes: the serial bytes for every split (2, 3 and 5 ranks: cuts inside maps and rows).
for spec in "ggx.yaml --method mis --samples 4 --seed 9" "ggx.yaml --method fis --samples 4 --normalise albedo" \
            "grey.yaml --method sh" "grey.yaml --method reference --reference-width 16"; do
  set -- $spec
  brdf=$1; shift
  "$rsibr" bake --env "$work/sky.exr" --brdf "$work/$brdf" --views icosa --res 11 "$@" -q "$work/serial.exr"
  for n in 2 3 5; do
    mpi $n "$rsibr" bake --env "$work/sky.exr" --brdf "$work/$brdf" --views icosa --res 11 "$@" -q "$work/mpi$n.exr" \
      --json "$work/mpi$n.json" >/dev/null 2>&1
    check "mpirun -n $n bake ($spec): the serial bytes" cmp -s "$work/serial.exr" "$work/mpi$n.exr"
  done
  check "mpirun bake: the summary counts the ranks" grep -q '"ranks": 5' "$work/mpi5.json"
done
check "mpirun bake: no temporaries" no_temporaries "$work"
mpi 2 "$rsibr" bake --env "$work/nosky.exr" --brdf "$work/ggx.yaml" --res 8 "$work/none.exr" >/dev/null 2>"$work/mpierr"
check "mpirun bake of a missing input fails" test $? -ne 0
check "mpirun bake: the error is printed once" test "$(grep -c 'nosky.exr' "$work/mpierr")" -eq 1
check "mpirun bake: no output after the error" test ! -e "$work/none.exr"
mpi 2 "$rsibr" info "$work/sky.exr" >/dev/null 2>"$work/mpiinfo"
check "mpirun of a one-process verb is refused" grep -q "runs as one process, not over 2 MPI ranks" "$work/mpiinfo"

# The batch over 2 ranks: job i on rank i mod 2, the broken one reported, 19 outputs.
rm -f "$work"/jobs/out*.exr
(cd "$work" && mpi 2 "$rsibr" batch jobs/batch.yaml --json mpi.json -q >/dev/null 2>"$work/mpibatch.err")
check "mpirun batch: exit non-zero when a job failed" test $? -ne 0
check "mpirun batch: 19 outputs" test "$(ls "$work/jobs" | grep -c '^out.*\.exr$')" -eq 19
check "mpirun batch: the summary lists every job and its rank" summary_is "$work/mpi.json" 19 1 2
check "mpirun batch: a job's bytes are the command's alone" cmp -s "$work/alone3.exr" "$work/jobs/out3.exr"
finish cluster_test
