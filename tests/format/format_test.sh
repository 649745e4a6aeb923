#!/usr/bin/env bash
# Every C++ source of the tree is as the repository's .clang-format writes it (clang-format 14,
# Debian 12's): a formatting difference fails, naming the files and how to fix them.
set -uo pipefail
root="$1"
cd "$root" || exit 1
format=$(command -v clang-format-14 || command -v clang-format) || {
  echo "clang-format is not installed (examples/setup.sh --with tests installs it)"; exit 1; }
if [ -d .git ] && command -v git > /dev/null; then
  mapfile -t files < <(git ls-files --cached --others --exclude-standard '*.h' '*.cc' '*.cpp' '*.hpp')
else
  mapfile -t files < <(find CMakeLists.txt OpenABLE descriptors matching config examples tests bench \
                         -name '*.h' -o -name '*.cc' -o -name '*.cpp' -o -name '*.hpp' 2> /dev/null)
fi
[ "${#files[@]}" -gt 100 ] || { echo "only ${#files[@]} C++ files found under $root"; exit 1; }
# One call over every file; each file that differs is named in its "error:" lines.
out=$("$format" --dry-run --Werror "${files[@]}" 2>&1); status=$?
mapfile -t bad < <(printf '%s\n' "$out" |
                   sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: error: .*clang-format-violations.*/\1/p' | sort -u)
if [ "$status" -ne 0 ] && [ "${#bad[@]}" -eq 0 ]; then
  echo "clang-format failed (exit $status): $(printf '%s\n' "$out" | head -n 3)"; exit 1
fi
if [ "${#bad[@]}" -gt 0 ]; then
  echo "${#bad[@]} of ${#files[@]} files are not formatted: ${bad[*]}"
  echo "fix: clang-format -i ${bad[*]}"
  exit 1
fi
echo "${#files[@]} files formatted"
