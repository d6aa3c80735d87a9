#!/usr/bin/env bash
# Re-runs this folder's measurements: the references, then every lever's `strata compare`
# (README.md here lists them), PARALLEL at a time (8 on the H200, where it all took about
# 6 minutes; 1 on lavapipe, where it would take roughly 15 h on a 2-core VM). Exits 1 when
# a reference or a run failed (each has its .log beside its output).
#
#   benchmarks/restir/h200_256/levers.sh STRATA SCENES OUT [PARALLEL]
#
# STRATA: a release `strata` binary; SCENES: the shared scenes' folder (scenes);
# OUT: where the references and one folder per run go.
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 STRATA SCENES OUT [PARALLEL]" >&2
  exit 2
fi
strata=$1 scenes=$2 out=$3 parallel=${4:-1}
mkdir -p "$out/refs"
# The scene argument and image size of each scene: 256 wide at its own aspect.
scene_args() {
  case $1 in
    default) echo "--width 256 --height 256" ;;
    cornell-box | objects-grid) echo "$scenes/$1/scene.json --width 256 --height 256" ;;
    matpreview) echo "$scenes/$1/scene.json --width 256 --height 192" ;;
    veach-ajar) echo "$scenes/$1/scene.json --width 256 --height 144" ;;
  esac
}
before="--shading sample --film white --min-roughness 0.2 --specular-chain 0"
pair="--seeds 32 --methods restir,strata"
# NAME|SCENE|FLAGS, in the order they ran.
job_list() {
  for s in default cornell-box matpreview objects-grid veach-ajar; do
    echo "$s.T_before|$s|$before"
    echo "$s.T_defaults|$s|"
    echo "$s.A_before|$s|--accumulate $before"
    echo "$s.A_defaults|$s|--accumulate"
  done
  for s in default cornell-box matpreview objects-grid veach-ajar; do
    echo "$s.T_shading|$s|--shading expectation --film white --min-roughness 0.2 --specular-chain 0"
    echo "$s.T_film|$s|--shading sample --film stratified --min-roughness 0.2 --specular-chain 0"
    echo "$s.T_cap5|$s|$before --temporal-cap 5"
    echo "$s.T_all|$s|--film stratified --temporal-cap 5"
    echo "$s.A_shading|$s|--accumulate --shading expectation --film white --min-roughness 0.2 --specular-chain 0"
    echo "$s.A_film|$s|--accumulate --shading sample --film stratified --min-roughness 0.2 --specular-chain 0"
  done
  for s in objects-grid veach-ajar; do
    echo "$s.T_glossy|$s|--shading sample --film white --min-roughness 0.05 --specular-chain 0"
    echo "$s.T_chain|$s|--shading sample --film white --min-roughness 0.2 --specular-chain 4"
    echo "$s.A_glossy|$s|--accumulate --shading sample --film white --min-roughness 0.05 --specular-chain 0"
    echo "$s.A_chain|$s|--accumulate --shading sample --film white --min-roughness 0.2 --specular-chain 4"
  done
  for s in default matpreview; do
    for b in 4 8 32; do
      echo "$s.T_B$b|$s|--block-size $b"
      echo "$s.A_B$b|$s|--accumulate --block-size $b"
    done
  done
  for s in veach-ajar objects-grid; do
    echo "$s.T_before_s32|$s|$before $pair"
    echo "$s.T_defaults_s32|$s|$pair"
  done
  echo "default.A_defaults_s32|default|--accumulate $pair"
  echo "default.A_B8_s32|default|--accumulate --block-size 8 $pair"
  echo "veach-ajar.A_before_s32|veach-ajar|--accumulate $before $pair"
  echo "veach-ajar.A_defaults_s32|veach-ajar|--accumulate $pair"
  echo "veach-ajar.T_all_s32|veach-ajar|--film stratified --temporal-cap 5 $pair"
  echo "veach-ajar.T_glossy_s32|veach-ajar|--shading sample --film white --min-roughness 0.05 --specular-chain 0 $pair"
  echo "veach-ajar.T_chain_s32|veach-ajar|--shading sample --film white --min-roughness 0.2 --specular-chain 4 $pair"
  echo "veach-ajar.A_glossy_s32|veach-ajar|--accumulate --shading sample --film white --min-roughness 0.05 --specular-chain 0 $pair"
  echo "veach-ajar.A_chain_s32|veach-ajar|--accumulate --shading sample --film white --min-roughness 0.2 --specular-chain 4 $pair"
  for s in default cornell-box matpreview objects-grid; do
    echo "$s.T_all_s32|$s|--film stratified --temporal-cap 5 $pair"
  done
  echo "veach-ajar.T_shading_s32|veach-ajar|--shading expectation --film white --min-roughness 0.2 --specular-chain 0 $pair"
  echo "veach-ajar.T_film_s32|veach-ajar|--shading sample --film stratified --min-roughness 0.2 --specular-chain 0 $pair"
  echo "veach-ajar.T_cap5_s32|veach-ajar|$before --temporal-cap 5 $pair"
}
for s in default cornell-box matpreview objects-grid veach-ajar; do
  # shellcheck disable=SC2046 # the scene arguments are words
  if ! "$strata" render $(scene_args $s) --spp 4096 --backend wgpu --out "$out/refs/$s" >"$out/refs/$s.log" 2>&1; then
    echo "reference $s FAILED (see $out/refs/$s.log)" >&2
    exit 1
  fi
done
run() {
  IFS='|' read -r name scene flags <<<"$1"
  seeds="--seeds 8"
  [[ $flags == *--seeds* ]] && seeds=""
  # shellcheck disable=SC2046,SC2086 # the arguments are words
  "$strata" compare $(scene_args "$scene") --frames 32 $seeds --reference "$out/refs/$scene/$scene.exr" \
    --backend wgpu --auto-crops 0 $flags --out "$out/$name" >"$out/$name.log" 2>&1 || {
    echo "$name FAILED (see $out/$name.log)" >&2
    return 1
  }
  echo "$name done"
}
export -f run scene_args
export strata scenes out
job_list | tr '\n' '\0' | xargs -0 -P "$parallel" -I{} bash -c 'run "$@"' _ {} || exit 1
