#!/usr/bin/env bash
# Builds the web page into web/dist/: index.html beside fourfold_web.js and its .wasm.
# Serve it with any static server, e.g.  python3 -m http.server -d web/dist
set -euo pipefail
cd "$(dirname "$0")/.."
fail() { echo "web/build.sh: $*" >&2; exit 1; }

command -v cargo >/dev/null || fail "cargo is missing: install Rust from https://rustup.rs"
if ! rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
  echo "adding the wasm32-unknown-unknown target…"
  rustup target add wasm32-unknown-unknown || fail "could not add the wasm32 target (rustup target add wasm32-unknown-unknown)"
fi

# wasm-bindgen must be the version of the wasm-bindgen crate in Cargo.lock.
version=$(grep -A1 '^name = "wasm-bindgen"$' Cargo.lock | sed -n 's/^version = "\(.*\)"/\1/p')
[ -n "$version" ] || fail "no wasm-bindgen in Cargo.lock"
if [ "$(wasm-bindgen --version 2>/dev/null | cut -d' ' -f2)" != "$version" ]; then
  echo "installing wasm-bindgen-cli $version (a few minutes, once)…"
  # (--locked first; a registry mirror may lack one of its locked dependencies.)
  cargo install wasm-bindgen-cli --version "$version" --locked --force \
    || cargo install wasm-bindgen-cli --version "$version" --force \
    || fail "could not install wasm-bindgen-cli $version (cargo install wasm-bindgen-cli --version $version)"
  command -v wasm-bindgen >/dev/null \
    || fail "wasm-bindgen was installed but is not on PATH: add ~/.cargo/bin to PATH"
fi

# The web profile (Cargo.toml) trades speed for size: the download comes before the first
# picture. wasm-opt shrinks the module further before wasm-bindgen writes the glue (binaryen
# 108, Debian's, renumbers the glue's externref table when it runs after).
cargo build --profile web --target wasm32-unknown-unknown -p fourfold-web \
  || fail "the wasm build failed (see above)"
wasm=target/wasm32-unknown-unknown/web/fourfold_web.wasm
if command -v wasm-opt >/dev/null; then
  echo "shrinking the wasm with $(wasm-opt --version)…"
  wasm-opt -Oz --enable-reference-types --enable-bulk-memory --enable-simd \
    --enable-nontrapping-float-to-int --enable-sign-ext --enable-mutable-globals \
    --enable-multivalue "$wasm" -o target/wasm32-unknown-unknown/web/fourfold_web.opt.wasm \
    || fail "wasm-opt failed (see above)"
  wasm=target/wasm32-unknown-unknown/web/fourfold_web.opt.wasm
else
  echo "web/build.sh: no wasm-opt (binaryen): the page's wasm stays larger than it need be;" >&2
  echo "  install it with: apt-get install binaryen" >&2
fi
rm -rf web/dist
mkdir -p web/dist
wasm-bindgen --target web --no-typescript --out-dir web/dist --out-name fourfold_web "$wasm" \
  || fail "wasm-bindgen could not make the JavaScript glue"
# The page's progress bar counts the download against the wasm's size.
bytes=$(wc -c < web/dist/fourfold_web_bg.wasm)
sed "s/@WASM_BYTES@/$bytes/" web/index.html > web/dist/index.html
echo "built web/dist ($(du -h web/dist/fourfold_web_bg.wasm | cut -f1) of wasm, $(gzip -9c web/dist/fourfold_web_bg.wasm | wc -c) bytes gzipped); serve it with:"
echo "  python3 -m http.server -d web/dist"
