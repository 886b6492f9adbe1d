# Sourced by the benchmark scripts: builds the CGAL anchor harness into $out/cgal (from
# $anchor_src, installing Debian's CGAL first if needed) unless it is there.
if ! [ -x "$out/cgal/cgal_anchor" ]; then
    if ! dpkg -s libcgal-dev >/dev/null 2>&1; then
        apt-get update -qq
        apt-get install -y -qq libcgal-dev libgmp-dev libmpfr-dev libboost-dev >/dev/null
    fi
    mkdir -p "$out/cgal"
    cp "$anchor_src/cgal_anchor.cpp" "$anchor_src/build.sh" "$out/cgal/"
    (cd "$out/cgal" && ./build.sh)
fi
