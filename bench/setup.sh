# Sourced by the benchmark scripts: `root` (the repository), `out` (bench/out, created) and
# `orb` (the release command line, built).
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=$root/bench/out
mkdir -p "$out"
cargo build --release -q -p orbitri-cli --manifest-path "$root/Cargo.toml"
orb=$root/target/release/orbitri
