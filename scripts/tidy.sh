#!/usr/bin/env bash
# clang-tidy (checks in .clang-tidy: bug-finding and performance, warnings are errors) on dcm's own .cpp files,
# with the release build's compile_commands.json. Kokkos, Eigen and the other libraries' headers are not
# checked (HeaderFilterRegex). ctest lint.clang-tidy runs it.
#   scripts/tidy.sh [FILE...]   (default: every tracked .cpp under core/, solvers/ and apps/)
# One clang-tidy per core at a time; DCM_TIDY_JOBS=N sets how many (ctest lint.clang-tidy: 2).
set -euo pipefail
cd "$(dirname "$0")/.."
tidy=$(command -v clang-tidy || command -v clang-tidy-14 || true)
[ -n "$tidy" ] || { echo "scripts/tidy.sh: clang-tidy not found (apt-get install clang-tidy)" >&2; exit 2; }
[ -f build/compile_commands.json ] || bash scripts/build.sh release > /dev/null
files=("$@")
[ ${#files[@]} -gt 0 ] || mapfile -t files < <(git ls-files 'core/*.cpp' 'solvers/*.cpp' 'apps/*.cpp')
# The build's commands without GCC's switches against gathers (CMakeLists.txt), which clang may refuse.
db=$(mktemp -d)
trap 'rm -rf "$db"' EXIT
sed -E -e 's/ (\\")?-mtune-ctrl=[^ "\\]*(\\")?//g' -e 's/ -mno-(gather|scatter)//g' build/compile_commands.json \
  > "$db/compile_commands.json"
# GCC's default dialect is C++17, so CMake records no -std flag; clang's is older.
printf '%s\n' "${files[@]}" | xargs -P "${DCM_TIDY_JOBS:-$(nproc)}" -n 1 "$tidy" -p "$db" --quiet \
  --extra-arg=-std=c++17 --extra-arg=-Wno-unknown-warning-option
echo "clang-tidy: ${#files[@]} files clean"
