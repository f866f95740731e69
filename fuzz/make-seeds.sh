#!/usr/bin/env bash
# Regenerates the seed corpora fuzz/corpus/<harness>/ with the project's own tools:
# `solidtex exemplar|analyze|field` from BUILD (default build/, `make build`), oiiotool
# (openimageio-tools) for the other image formats, and small hand-written meshes, JSON and
# query strings. Every seed stays a few KB. The fuzzers' own findings go to
# build-fuzz/corpus/ (scripts/run-fuzz.sh), never here.
# Usage: fuzz/make-seeds.sh [BUILD]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
st="$build/bin/solidtex"
[ -x "$st" ] || { echo "make-seeds: $st not found (make build first)" >&2; exit 1; }
out="$root/fuzz/corpus"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for h in image mesh table field_file sketch field_spec params query; do
  rm -rf "${out:?}/$h"
  mkdir -p "$out/$h"
done
# put HARNESS NAME TEXT: a seed from a printf format (so \x00 selector bytes are possible).
put() { printf "$3" > "$out/$1/$2"; }
# quiet CMD...: runs CMD, showing its output only when it fails.
quiet() { "$@" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; exit 1; }; }

# ---- image: decode_image ------------------------------------------------------------------
quiet "$st" exemplar wood --size 16,16 -o "$out/image/wood16.png"
quiet "$st" exemplar stripes --size 8,12 -o "$tmp/stripes.png"
cp "$tmp/stripes.png" "$out/image/stripes8x12.png"
# No command line, temporary paths or dates in the seeds: they stay byte-for-byte reproducible.
convert() { oiiotool -q --nosoftwareattrib "$tmp/stripes.png" --eraseattrib ".*" --attrib DateTime "2000:01:01 00:00:00" "$@"; }
convert -o "$out/image/stripes.jpg"
convert --compression none -o "$out/image/stripes.tif"
convert -d half --compression zip -o "$out/image/stripes.exr"
convert --ch R -d uint16 -o "$out/image/gray16.png"
convert --ch R,G,B,A=1.0 -o "$out/image/rgba.png"
# Reproducers of decode_image findings (fuzz/README.md), made from stripes.exr (8x12, one zip
# chunk): that chunk replaced by a zlib stream of 10 bytes where 576 are needed (OpenEXR's
# classic reader returned uninitialised memory as pixels), and its chunk table entry set to -8
# (OIIO 2.4's IOMemReader::pread then read the 8 bytes before the buffer).
python3 - "$out/image" <<'EOF'
import struct, sys
d = sys.argv[1]
b = open(f"{d}/stripes.exr", "rb").read()
i = 8
while b[i] != 0:  # the attributes: name\0 type\0 i32 size, value; the header ends with \0
    i = b.index(b"\0", b.index(b"\0", i) + 1) + 1
    i += 4 + struct.unpack_from("<i", b, i)[0]
table = i + 1
chunk = struct.unpack_from("<Q", b, table)[0]
short = bytes.fromhex("789c6360800100000a0001")  # zlib stream of 10 zero bytes
open(f"{d}/repro_exr_short_zip_chunk.exr", "wb").write(b[:chunk + 4] + struct.pack("<i", len(short)) + short)
open(f"{d}/repro_exr_chunk_offset_minus8.exr", "wb").write(b[:table] + struct.pack("<q", -8) + b[table + 8:])
EOF

# ---- mesh: decode_mesh ---------------------------------------------------------------------
put mesh tetra.obj '# tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n'
put mesh quad_negative.obj 'o q\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf -4/1/1 -3/1/1 -2/1/1 -1/1/1\nf 1 2 3\nf 1 1 2\n'
put mesh tetra.off 'OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n'
put mesh square.coff 'COFF 4 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 255 255\n0 1 0 9 9 9 255\n4 0 1 2 3\n'
put mesh tetra_ascii.ply 'ply\nformat ascii 1.0\ncomment seed\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0 1\n1 0 0 2\n0 1 0 3\n0 0 1 4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n'
python3 - "$out/mesh" <<'EOF'
import struct, sys
d = sys.argv[1]
verts = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
for name, fmt, e in (("tetra_le.ply", "binary_little_endian", "<"), ("tetra_be.ply", "binary_big_endian", ">")):
    head = (f"ply\nformat {fmt} 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 4\nproperty list uchar int vertex_indices\nend_header\n").encode()
    body = b"".join(struct.pack(e + "3f", *v) for v in verts)
    body += b"".join(struct.pack(e + "B3i", 3, *f) for f in faces)
    open(f"{d}/{name}", "wb").write(head + body)
# doubles, a ushort list count, an extra element and property
head = ("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
        "property double z\nproperty short flags\nelement face 2\nproperty list ushort uint vertex_index\n"
        "property float quality\nelement edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n").encode()
body = b"".join(struct.pack("<3dh", *v, 7) for v in verts)
body += struct.pack("<H4If", 4, 0, 1, 2, 3, 0.5) + struct.pack("<H3If", 3, 0, 2, 1, 1.5)
body += struct.pack("<2i", 0, 1)
open(f"{d}/mixed_types.ply", "wb").write(head + body)
EOF

# ---- table (.stx): decode_table -------------------------------------------------------------
quiet "$st" exemplar noise --size 8,8 -o "$tmp/e8.png"
quiet "$st" exemplar spots --size 8,8 --seed 2 -o "$tmp/f8.png"
quiet "$st" exemplar bricks --size 8,8 --seed 3 -o "$tmp/g8.png"
tiny=(--levels 1 --neighborhood 3 --candidates 1 --pca-dims 2 --threads 1)
quiet "$st" analyze "$tmp/e8.png" "${tiny[@]}" -o "$out/table/shared_1level.stx"
quiet "$st" analyze "$tmp/e8.png" --levels 2 --neighborhood 3 --candidates 2 --pca-dims 2 --threads 1 \
  -o "$out/table/shared_2levels.stx"
quiet "$st" analyze "$tmp/e8.png" --yz "$tmp/f8.png" --zx "$tmp/g8.png" "${tiny[@]}" -o "$out/table/three_planes.stx"
quiet "$st" analyze "$tmp/e8.png" --mask "$tmp/f8.png" "${tiny[@]}" -o "$out/table/masked.stx"

# ---- sketches (also the field files' source) -----------------------------------------------
cat > "$tmp/plane.json" <<'EOF'
{"domain": {"min": [0, 0, 0], "max": [8, 8, 8], "shortest_side_cells": 2},
 "curves": [{"points": [[1, 1, 1], [4, 2, 1], [7, 4, 2]], "plane_normal": [0, 0, 1], "axis": "x", "weight": 50}]}
EOF
cat > "$tmp/surface.json" <<'EOF'
{"domain": {"min": [-4, 0, 0], "max": [4, 6, 3], "shortest_side_cells": 2},
 "curves": [{"points": [[-3, 1, 1], [0, 2, 1.5], [3, 5, 2]], "normals": [[0, 0, 1], [0, 0.6, 0.8], [0, 1, 0]]},
            {"points": [[-3, 5, 0.5], [3, 5, 0.5]], "plane_normal": [0, 1, 0], "axis": "z"}],
 "scales": [{"point": [0, 3, 1], "scale": [2, 1, 0.5], "weight": 10}]}
EOF
cat > "$tmp/frames.json" <<'EOF'
{"domain": {"min": [0, 0, 0], "max": [4, 4, 4], "shortest_side_cells": 2}, "curves": [],
 "frames": [{"point": [1, 1, 1], "quaternion": [0.92, 0, 0, 0.38]}, {"point": [3, 3, 3], "quaternion": [1, 0, 0, 0], "weight": 5}]}
EOF
for s in plane surface frames; do cp "$tmp/$s.json" "$out/sketch/$s.json"; done
put sketch curve.json '{"points": [[0, 0, 0], [10, 0, 0]], "plane_normal": [0, 1, 0], "axis": "y", "weight": 1e6}'
put sketch bad_duplicate.json '{"domain": {"min": [0, 0, 0], "min": [1, 1, 1]}}'

# ---- field file (.stf): decode_field ----------------------------------------------------------
quiet "$st" field "$tmp/plane.json" -o "$out/field_file/plane.stf"
quiet "$st" field "$tmp/surface.json" -o "$out/field_file/scaled.stf"
quiet "$st" field "$tmp/frames.json" -o "$out/field_file/frames.stf"
# Reproducer of the at(origin) finding (fuzz/README.md): plane.stf with node 0 = (1e200, 0, 0,
# 1e200), whose squared norm overflows. Its checksum is stale; the harness also decodes it with
# the checksum fixed (fuzz_support.h).
python3 - "$out/field_file" <<'EOF'
import struct, sys
d = sys.argv[1]
b = bytearray(open(f"{d}/plane.stf", "rb").read())
struct.pack_into("<4d", b, 32 + 48, 1e200, 0.0, 0.0, 1e200)  # after the header, origin, spacing, dims, count
open(f"{d}/repro_huge_quaternion.stf", "wb").write(bytes(b))
EOF

# ---- field_spec: first byte 0 "identity;scale:", 1 "quat:", 2 "axis:" -----------------------
put field_spec identity_scale '\x001,2,0.5'
put field_spec quat '\x010.92,0,0,0.38'
put field_spec quat_scale '\x011,0,0,0;scale:4,0.25,1'
put field_spec axis '\x020,0,1,30'
put field_spec axis_scale '\x021,1,0,-45.5;scale:1.5,1.5,1.5'

# ---- params: analysis, synthesis and placement JSON ------------------------------------------
put params analysis.json '{"levels": 3, "neighborhood": 7, "candidates": 12, "pca_dims": 20, "search_k": 8, "knn_checks": 64, "seed": 5, "suggested_plane_weights": [1, 0.1, 1]}'
put params synthesis.json '{"scheme": "dual-grid", "matcher": "coherent", "coarse_passes": 2, "passes": 1, "subpass_size": 2, "cell_size": 8, "init_subpart": 32, "trilinear_levels": 1, "plane_weights": [1, 0.5, 1]}'
put params scheme_renamed.json '{"scheme": "standard", "matcher": "paper"}'
put params placement_fit.json '{"resolution": 64, "margin": 0.1}'
put params placement_scale.json '{"scale": 2.5, "translate": [1, -2, 3.5]}'

# ---- query: first byte picks the route's keys (fuzz/query_fuzzer.cpp kRoutes) ----------------
put query slice '\x05axis=z&at=-3&origin=1,2&size=16,16&timeout=2.5'
put query upload '\x03name=wood%%20x&levels=3&neighborhood=7&candidates=4&pca_dims=8&seed=9&plane_weights=1,0.1,1&grain=x&mask_weight=0.5'
put query frames '\x04min=0,0.5,0&size=4,4,4&step=1e-2'
put query region '\x06min=-8,0,8&size=2,3,4'
put query surface '\x07resolution=64&margin=0.1&format=json&timeout=1'
put query none '\x00'

du -sh "$out"/* | sed 's|'"$root"'/||'
