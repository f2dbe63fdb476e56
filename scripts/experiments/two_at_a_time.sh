# Sourced by the ablation scripts: two_at_a_time FUNCTION ITEM...
# Runs FUNCTION on the first item alone (it fills the shared detection cache), then on the others two at a time
# (one thread each on the 2-core machine).
two_at_a_time() {
  local fn=$1
  shift
  local items=("$@")
  "$fn" "${items[0]}"
  for ((i = 1; i < ${#items[@]}; i += 2)); do
    "$fn" "${items[$i]}" &
    if ((i + 1 < ${#items[@]})); then "$fn" "${items[$((i + 1))]}"; fi
    wait
  done
}
