#!/usr/bin/env bash
# build.sh — one entry point for building, serving and testing the lab.
#
#   ./build.sh serve         build, then serve the lab on http://127.0.0.1:8000
#   ./build.sh test          every check CI runs (fmt, clippy, native tests, wasm
#                            tests in node with and without SIMD128, CLI and
#                            browser end-to-end tests)
#   ./build.sh build         release wasm with SIMD128 + JS bindings into web/pkg
#   ./build.sh build-scalar  the same without SIMD128 into web/pkg-scalar
#   ./build.sh bench         the benchmarks behind BENCHMARKS.md
#   ./build.sh test-real     the real-data suite: real maps and laser logs read
#                            from ../shared/data (fails when it is missing)
#
# Each command installs what is missing (the wasm32 target, the wasm-bindgen
# CLI pinned to the version in Cargo.lock, Debian's chromium + chromium-driver,
# npm's playwright-core) and skips what is already there.
set -euo pipefail
cd "$(dirname "$0")"
ROOT=$(pwd)
export PATH="$HOME/.cargo/bin:$PATH"
SIMD_FLAGS='-C target-feature=+simd128'
# The real-data suite's test files (each fails loudly without ../shared/data).
REAL_RUST_TESTS='--test real_maps --test real_logs --test real_bags --test real_bag_containers --test real_bag_db3'
REAL_NODE_TESTS='tests/real-bags.test.mjs tests/page-bags.test.mjs'

log() { printf '\033[1;34m==>\033[0m %s\n' "$*" >&2; }

as_root() {
  if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else
    echo "need root to run: $*" >&2; return 1; fi
}

ensure_wasm_target() {
  if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    log "installing the wasm32-unknown-unknown target"
    rustup target add wasm32-unknown-unknown
  fi
}

# The wasm-bindgen CLI must equal the wasm-bindgen crate version in Cargo.lock.
ensure_wasm_bindgen() {
  [ -f Cargo.lock ] || cargo generate-lockfile
  local want have
  want=$(awk '/^name = "wasm-bindgen"$/ {getline; gsub(/version = |"/, ""); print; exit}' Cargo.lock)
  have=$(wasm-bindgen --version 2>/dev/null | awk '{print $2}' || true)
  if [ "$have" != "$want" ] || ! command -v wasm-bindgen-test-runner >/dev/null; then
    log "installing wasm-bindgen-cli $want (about 12 minutes on 2 cores)"
    # --locked fails here: its lockfile wants a crate version the registry lacks.
    cargo install wasm-bindgen-cli --version "=$want"
  fi
}

ensure_chromium() {
  if ! command -v chromium >/dev/null || ! command -v chromedriver >/dev/null; then
    log "installing Debian's chromium and chromium-driver"
    as_root apt-get update -qq
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium chromium-driver >/dev/null
  fi
}

ensure_node_modules() {
  if [ ! -d node_modules/playwright-core ]; then
    log "installing npm dev dependencies (playwright-core; it drives /usr/bin/chromium and downloads no browser)"
    npm ci --no-audit --no-fund --loglevel=error
  fi
}

# build_wasm OUT_DIR TARGET_DIR RUSTFLAGS
build_wasm() {
  local out=$1 tdir=$2 flags=$3
  ensure_wasm_target
  ensure_wasm_bindgen
  log "building wasm ($([ -n "$flags" ] && echo SIMD128 || echo scalar)) into $out"
  CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS="$flags" \
    cargo build --release --lib --target wasm32-unknown-unknown --target-dir "$tdir" -p slamlab
  wasm-bindgen --target web --out-dir "$out" "$tdir/wasm32-unknown-unknown/release/slamlab.wasm"
}

cmd_build() { build_wasm web/pkg target/wasm-simd "$SIMD_FLAGS"; }
cmd_build_scalar() { build_wasm web/pkg-scalar target/wasm-scalar ""; }

cmd_serve() {
  cmd_build
  local port=${PORT:-8000}
  log "serving $ROOT"
  echo "Open http://127.0.0.1:$port/ in a browser (Ctrl-C stops the server)."
  exec python3 -m http.server "$port" --bind 127.0.0.1
}

# Runs the wasm test suite in node. $1 = label, $2 = target dir, $3 = RUSTFLAGS.
wasm_tests() {
  log "wasm tests in node ($1)"
  CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS="$3" WASM_BINDGEN_TEST_ONLY_NODE=1 \
    cargo test --target wasm32-unknown-unknown --target-dir "$2" -p slamlab --tests
}

cmd_test() {
  ensure_wasm_target
  ensure_wasm_bindgen
  ensure_chromium
  ensure_node_modules
  log "cargo fmt --check"
  cargo fmt --all -- --check
  log "cargo clippy (native and wasm32) -D warnings"
  cargo clippy --all-targets -p slamlab -- -D warnings
  CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS="$SIMD_FLAGS" \
    cargo clippy --target wasm32-unknown-unknown --target-dir target/wasm-simd --all-targets -p slamlab -- -D warnings
  log "native tests"
  cargo test -p slamlab
  wasm_tests "SIMD128" target/wasm-simd "$SIMD_FLAGS"
  wasm_tests "scalar" target/wasm-scalar ""
  cmd_build
  log "command-line and browser end-to-end tests (node --test)"
  mkdir -p test-artifacts
  node --test --test-concurrency=1 tests/imports.test.mjs tests/lab.test.mjs tests/cli.test.mjs tests/maps.test.mjs tests/bag-maps.test.mjs tests/run-log.test.mjs tests/bag-inputs.test.mjs tests/log-merge.test.mjs tests/reports.test.mjs tests/crowd.test.mjs tests/exercises.test.mjs tests/page.test.mjs tests/page-real.test.mjs tests/page-groups.test.mjs tests/classroom.test.mjs tests/page-lab-ux.test.mjs tests/page-maps-ux.test.mjs tests/page-log-ux.test.mjs tests/page-log-groups.test.mjs
}

# The real-data suite reads third-party data from ../shared/data (or
# $SLAMLAB_DATA); it is never copied into the repository. Missing data is a
# failure, not a skip.
data_dir() { echo "${SLAMLAB_DATA:-$ROOT/../shared/data}"; }

cmd_test_real() {
  local data
  data=$(data_dir)
  if [ ! -f "$data/README.md" ]; then
    echo "error: the real-data suite needs ../shared/data (or SLAMLAB_DATA); not found at $data" >&2
    exit 1
  fi
  export SLAMLAB_DATA="$data"
  ensure_node_modules
  cmd_build
  if [ -z "$REAL_RUST_TESTS$REAL_NODE_TESTS" ]; then
    echo "error: no real-data tests are registered in build.sh" >&2
    exit 1
  fi
  if [ -n "$REAL_RUST_TESTS" ]; then
    log "real-data tests: native (release)"
    # shellcheck disable=SC2086
    cargo test --release -p slamlab --features real-data $REAL_RUST_TESTS
  fi
  if [ -n "$REAL_NODE_TESTS" ]; then
    log "real-data tests: command line (node --test)"
    # shellcheck disable=SC2086
    node --test --test-concurrency=1 $REAL_NODE_TESTS
  fi
}

cmd_bench() {
  cmd_build
  log "native simulation benchmark"
  cargo run --release -p slamlab --example bench_sim
  log "wasm simulation and rendering benchmark in node"
  node tests/bench/sim.mjs
}

case "${1:-}" in
  build) cmd_build ;;
  build-scalar) cmd_build_scalar ;;
  serve) cmd_serve ;;
  test) cmd_test ;;
  bench) cmd_bench ;;
  test-real) cmd_test_real ;;
  *) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
esac
