#!/usr/bin/env bash
# versitygw: the S3-compatible server solidtex tests and `make cluster` run against
# (docs/design/scale-out-research.md: real, AWS-strict about signing, passes every
# conditional-write test, light). The binary is built once per version from the Go module
# proxy and cached outside the repository, so a fresh clone pays ~4 CPU-minutes once.
#
#   scripts/versitygw.sh build           builds if not cached (needs `go`), prints the binary path
#   scripts/versitygw.sh path            prints the cached binary path; exit 1 if it is not built
#                                        (never builds: tests use this to decide to skip)
#   scripts/versitygw.sh run PORT DIR    execs versitygw on 127.0.0.1:PORT serving DIR, building
#                                        first if needed. Every subdirectory of DIR is a bucket;
#                                        the bucket named by $VERSITYGW_BUCKET (default "solidtex")
#                                        is created. Credentials: $ROOT_ACCESS_KEY / $ROOT_SECRET_KEY
#                                        (default solidtex / solidtex-secret); give solidtex the same
#                                        pair as AWS_ACCESS_KEY_ID / AWS_SECRET_ACCESS_KEY.
#
# Cache: ${XDG_CACHE_HOME:-$HOME/.cache}/solidtex/versitygw-v1.8.0/versitygw. The DIR filesystem
# needs user xattrs (ext4 and tmpfs do); versitygw keeps ETags in them.
set -euo pipefail
version=v1.8.0
cache=${XDG_CACHE_HOME:-$HOME/.cache}/solidtex/versitygw-$version
bin=$cache/versitygw

build() {
  if [ -x "$bin" ]; then echo "$bin"; return; fi
  command -v go >/dev/null || { echo "versitygw.sh: 'go' is not installed; cannot build versitygw $version" >&2; exit 1; }
  mkdir -p "$cache"
  # Build into a temporary GOBIN and rename, so an interrupted build never leaves a partial
  # binary that later runs would take for a cached one.
  tmp=$(mktemp -d "$cache/build.XXXXXX")
  trap 'rm -rf "$tmp"' EXIT
  echo "versitygw.sh: building versitygw $version (about 4 CPU-minutes, once)" >&2
  GOBIN=$tmp GOFLAGS=-trimpath nice -n 19 go install "github.com/versity/versitygw/cmd/versitygw@$version" >&2
  mv "$tmp/versitygw" "$bin"
  echo "$bin"
}

case "${1:-}" in
  build) build ;;
  path)
    if [ -x "$bin" ]; then echo "$bin"; else echo "versitygw.sh: $bin is not built (run scripts/versitygw.sh build)" >&2; exit 1; fi ;;
  run)
    [ $# -eq 3 ] || { echo "usage: $0 run PORT DIR" >&2; exit 2; }
    port=$2 dir=$3
    build >/dev/null
    mkdir -p "$dir/${VERSITYGW_BUCKET:-solidtex}"
    export ROOT_ACCESS_KEY=${ROOT_ACCESS_KEY:-solidtex} ROOT_SECRET_KEY=${ROOT_SECRET_KEY:-solidtex-secret}
    exec "$bin" --port "127.0.0.1:$port" posix "$dir" ;;
  *)
    echo "usage: $0 build | path | run PORT DIR" >&2; exit 2 ;;
esac
