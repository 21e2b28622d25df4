# Sourced by scripts/sanitize.sh and scripts/fuzz.sh: the clang build of test/sanitize/ in
# .sanitize_build/ (git-ignored; SIFT_HULL_SANITIZE_BUILD moves it).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
sanitize_build="$(realpath -m "${SIFT_HULL_SANITIZE_BUILD:-$repo_root/.sanitize_build}")"
mkdir -p "$sanitize_build"
junit=(/usr/bin/python3 "$repo_root/scripts/junit.py")

# The sanitizer runtimes print symbolised stacks with llvm-symbolizer.
if [[ -z "${ASAN_SYMBOLIZER_PATH:-}" && -x /usr/lib/llvm-14/bin/llvm-symbolizer ]]; then
  export ASAN_SYMBOLIZER_PATH=/usr/lib/llvm-14/bin/llvm-symbolizer
fi

# Configures the build (installing what scripts/apt-packages.txt lists, clang included, when it is
# missing) and builds target $1 with nice -n 10 and $SANITIZE_JOBS (default 2) jobs; the log is $2.
# Further arguments are passed to cmake's configure step.
build_sanitized() {
  local target="$1" log="$2"
  shift 2
  bash "$repo_root/scripts/setup.sh" >&2
  {
    cmake -S "$repo_root/test/sanitize" -B "$sanitize_build" -DCMAKE_CXX_COMPILER=clang++ "$@" &&
      nice -n 10 cmake --build "$sanitize_build" --target "$target" -- -j"${SANITIZE_JOBS:-2}"
  } >"$log" 2>&1
}
