#!/bin/sh
# Two frames of each animation, as PNG, for the guide: Debian's chromium
# (apt install chromium) plays the SVG for a little and a little more
# virtual time. Run from the repository root after
# `cargo run --release --example animations`.
set -e
out=docs/guide/pictures
mkdir -p "$out"
shot() {
    profile=$(mktemp -d)
    chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
        --disable-background-networking --disable-component-update --disable-sync \
        --hide-scrollbars --user-data-dir="$profile" --window-size="$4" \
        --virtual-time-budget="$2" --screenshot="$3" "file://$PWD/$1" 2>/dev/null
    rm -rf "$profile"
}
for svg in docs/animations/*.svg; do
    name=$(basename "$svg" .svg)
    case "$name" in
    *eigenvalues) shot "$svg" 100 "$out/$name.png" 640,420 ;;
    *)
        shot "$svg" 1800 "$out/${name}_1.png" 640,480
        shot "$svg" 4200 "$out/${name}_2.png" 640,480
        ;;
    esac
done
