# Sourced by the scripts that need a simulated data set: simulate_once DIR CONFIG SEQUENCES FRAMES SEED [LOG]
# runs `ret3d sim` into DIR unless a finished run is there already (DIR/.done; a half-written DIR is redone).
# Output goes to LOG (default: the terminal).
simulate_once() {
  local dir=$1 config=$2 sequences=$3 frames=$4 seed=$5 log=${6:-/dev/stdout}
  [ -f "$dir/.done" ] && return 0
  rm -rf "$dir"
  ret3d sim --config "$config" --out "$dir" --sequences "$sequences" --frames "$frames" --seed "$seed" >"$log" 2>&1
  touch "$dir/.done"
}
