# Sourced by the MPI test scripts (which define fail()).
# same_csv DIR_A DIR_B: every CSV file of A in B, byte for byte, and as many (at least 2).
same_csv() {
  local a=$1 b=$2 f n=0
  for f in "$a"/*.csv; do
    cmp "$f" "$b/$(basename "$f")" || fail "$(basename "$f"): $a and $b differ"
    n=$((n + 1))
  done
  [ "$n" -ge 2 ] || fail "$a holds $n CSV files"
  [ "$(ls "$b"/*.csv | wc -l)" -eq "$n" ] || fail "$b holds other CSV files than $a"
}
