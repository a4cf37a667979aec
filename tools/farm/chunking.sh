# Sourced by the farm scripts: checks FIRST END CHUNK and sets `shards`, refusing a chunk of 0 or a
# range that does not divide into chunks, with a message naming the script ($script).
farm_fail() {
  echo "$script: $*" >&2
  exit 1
}

check_chunking() {  # FIRST END CHUNK
  local name value
  for name in FIRST END CHUNK; do
    value="$1"
    shift
    [[ "$value" =~ ^[0-9]+$ ]] && [ "${#value}" -le 9 ] ||
      farm_fail "$name must be a whole number, not '$value'"
    printf -v "${name,,}" '%d' "$((10#$value))"
  done
  [ "$chunk" -gt 0 ] || farm_fail "CHUNK must be at least 1 frame"
  [ "$end" -gt "$first" ] || farm_fail "the range $first..$end is empty (END must be above FIRST)"
  local frames=$((end - first))
  [ $((frames % chunk)) -eq 0 ] ||
    farm_fail "the range's $frames frames do not divide into chunks of $chunk (choose a divisor of $frames)"
  shards=$((frames / chunk))
}
