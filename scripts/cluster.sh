#!/usr/bin/env bash
# The local reference deployment of issue #16 (deploy/README.md): N `solidtex serve` replicas
# behind nginx (deploy/nginx/nginx.conf.template), all on 127.0.0.1.
#
#   scripts/cluster.sh [up]          starts the storage (S3 server when CLUSTER_STORAGE=s3), the
#                                    replicas and nginx, prints the URL, serves until Ctrl-C
#                                    (or SIGTERM), then stops everything it started
#   scripts/cluster.sh deps          installs Debian's nginx when it is missing (apt, as
#                                    scripts/install-deps.sh does; not part of `make test`)
#   scripts/cluster.sh render FILE   writes the nginx.conf `up` would use (for CLUSTER_DIR)
#   scripts/cluster.sh k8s-configmap prints deploy/k8s/nginx-configmap.yaml (the same template
#                                    rendered for Kubernetes; K8S_REPLICAS upstreams, default 3)
#
# Environment:
#   CLUSTER_DIR       runtime and data directory (build/cluster); data survive restarts
#   CLUSTER_PORT      nginx's port (8090); replica i (1..N) listens on CLUSTER_PORT+i, the S3
#                     server on CLUSTER_PORT+20
#   CLUSTER_REPLICAS  N (3)
#   CLUSTER_STORAGE   dir: every replica on one --data directory (CLUSTER_DIR/data);
#                     s3: versitygw (scripts/versitygw.sh) on CLUSTER_DIR/s3, replicas on
#                     --storage s3://solidtex/cluster
#   CLUSTER_BALANCE   hash (consistent hashing on the affinity key) or round-robin
#   CLUSTER_NGINX_CACHE  on, or off to measure the replicas without nginx's cache
#   CLUSTER_SERVE_FLAGS  extra `solidtex serve` flags for every replica (e.g. "--threads 1")
#   CLUSTER_RESTART_DELAY  seconds the supervisor waits before restarting a dead nginx or S3
#                     server (1; the cluster test lengthens the outage it causes)
#   SOLIDTEX_BIN      the solidtex executable (build/bin/solidtex)
#
# When everything answers, CLUSTER_DIR/cluster.json describes the running cluster (urls, pids,
# each replica's command line and environment: the cluster test kills and restarts replicas).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

# ---- configuration ------------------------------------------------------------------------
storage=${CLUSTER_STORAGE:-s3}   # the storage every replica shares: s3 | dir
dir=$(mkdir -p "${CLUSTER_DIR:-$root/build/cluster}" && cd "${CLUSTER_DIR:-$root/build/cluster}" && pwd)
port=${CLUSTER_PORT:-8090}
replicas=${CLUSTER_REPLICAS:-3}
balance=${CLUSTER_BALANCE:-hash}
nginx_cache=${CLUSTER_NGINX_CACHE:-on}
restart_delay=${CLUSTER_RESTART_DELAY:-1}
bin=${SOLIDTEX_BIN:-$root/build/bin/solidtex}
host=127.0.0.1
s3_port=$((port + 20))
s3_bucket=solidtex
s3_prefix=cluster
template=$root/deploy/nginx/nginx.conf.template
# One synthesis worker and 256 MiB of voxel cache per replica: three replicas share 2 cores here.
# A queue of 64 absorbs bursts that would otherwise be 503s (which nginx counts as failures).
serve_flags="--threads 1 --queue 64 --cache-mb 256 ${CLUSTER_SERVE_FLAGS:-}"

nginx_bin() { command -v nginx 2>/dev/null || { [ -x /usr/sbin/nginx ] && echo /usr/sbin/nginx; } || true; }

install_nginx() {
  [ -n "$(nginx_bin)" ] && return 0
  echo "cluster: installing Debian's nginx (the balancer of make cluster)"
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  # The package's own service (port 80) is not used: the cluster runs its own nginx instance.
  $sudo apt-get install -y -qq --no-install-recommends nginx >/dev/null
  [ -n "$(nginx_bin)" ] || { echo "cluster: nginx did not install" >&2; exit 1; }
}

# render OUT PREFIX LISTEN WORKERS ERROR_LOG ACCESS_LOG CACHE_MAX BALANCE IMAGE_TTL USER CACHE SERVER...
render() {
  python3 - "$template" "$@" <<'PY'
import sys
template, out, prefix, listen, workers, error_log, access_log, cache_max, balance, ttl, user, cache, *servers = sys.argv[1:]
directive = {"hash": "hash $solidtex_affinity consistent;", "round-robin": "# round-robin"}[balance]
lines = "\n".join(f"        server {s} max_fails=3 fail_timeout=3s;" for s in servers)
values = {"@PREFIX@": prefix, "@LISTEN@": listen, "@WORKERS@": workers, "@ERROR_LOG@": error_log,
          "@ACCESS_LOG@": access_log, "@CACHE_MAX_SIZE@": cache_max, "@BALANCE@": directive,
          "@SERVERS@": lines, "@IMAGE_TTL@": ttl,
          "@USER@": f"user {user};" if user else "# workers run as the master's user",
          "@CACHE@": {"on": "solidtex", "off": "off"}[cache]}
out_lines = []
for line in open(template).read().splitlines():
    if not line.lstrip().startswith("#"):  # comments name the placeholders
        for key, value in values.items():
            line = line.replace(key, value)
        assert "@" not in line, f"unrendered placeholder in {line!r}"
    out_lines.append(line)
with open(out, "w") if out != "-" else sys.stdout as f:
    f.write("\n".join(out_lines) + "\n")
PY
}

render_local() {  # OUT
  local servers=() i
  for i in $(seq 1 "$replicas"); do servers+=("$host:$((port + i))"); done
  case "$balance" in hash|round-robin) ;; *) echo "cluster: CLUSTER_BALANCE must be hash or round-robin" >&2; exit 2 ;; esac
  render "$1" "$dir/nginx" "$host:$port" 1 "$dir/nginx/error.log" "$dir/nginx/access.log" 1g "$balance" 10m \
    "$([ "$(id -u)" -eq 0 ] && echo root)" "$nginx_cache" "${servers[@]}"
}

k8s_configmap() {
  local conf servers=() i
  for i in $(seq 0 $((${K8S_REPLICAS:-3} - 1))); do servers+=("solidtex-$i:8080"); done
  conf=$(render - /var/cache/nginx-solidtex 8080 auto stderr /dev/stdout 4g hash 10m "" on "${servers[@]}")
  cat <<'EOF'
# GENERATED by `scripts/cluster.sh k8s-configmap > deploy/k8s/nginx-configmap.yaml` from
# deploy/nginx/nginx.conf.template (tests/cluster/test_cluster.py checks it is up to date).
# The upstream names are the per-replica Services of solidtex.yaml (stable ClusterIPs: nginx
# resolves them once, at start).
apiVersion: v1
kind: ConfigMap
metadata:
  name: solidtex-nginx
  labels:
    app.kubernetes.io/name: solidtex-nginx
data:
  nginx.conf: |
EOF
  printf '%s\n' "$conf" | sed 's/^\(.\)/    \1/'
}

wait_http() {  # URL SECONDS PID WHAT
  local end=$((SECONDS + $2))
  while [ $SECONDS -lt $end ]; do
    curl -sf -o /dev/null --max-time 2 "$1" && return 0
    if [ -n "$3" ] && ! kill -0 "$3" 2>/dev/null; then echo "cluster: $4 exited before answering $1" >&2; return 1; fi
    sleep 0.1
  done
  echo "cluster: $4 did not answer $1 within $2 s" >&2
  return 1
}

pids=()
stop_all() {
  trap - EXIT INT TERM
  local p
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  rm -f "$dir/cluster.json"
}

# nginx and the S3 server are supervised as a container runtime would (deploy/k8s restarts a
# crashed pod): when either dies it is started again, so killing one (the cluster test does,
# with kill -9) is an outage, not the end of the cluster. Replicas are not: the cluster test
# kills and restarts them itself, to watch the balancer route around a dead one.
store_pid="" nginx_pid="" store_kind="" store_key="" store_secret="" env_json="{}" replicas_json=""

start_store() {  # versitygw on $s3_port serving $dir/s3; sets store_pid
  ROOT_ACCESS_KEY=$store_key ROOT_SECRET_KEY=$store_secret VERSITYGW_BUCKET=$s3_bucket \
    "$root/scripts/versitygw.sh" run "$s3_port" "$dir/s3" >>"$dir/logs/s3.log" 2>&1 &
  store_pid=$!
  store_kind=s3
  pids+=("$store_pid")
  local end=$((SECONDS + 30))
  until curl -s -o /dev/null --max-time 2 "http://$host:$s3_port/"; do
    kill -0 "$store_pid" 2>/dev/null || { echo "cluster: the S3 server exited (see $dir/logs/s3.log)" >&2; return 1; }
    [ $SECONDS -lt $end ] || { echo "cluster: the S3 server did not answer" >&2; return 1; }
    sleep 0.1
  done
}

start_nginx() {  # nginx in the foreground (daemon off), leading its own process group; sets nginx_pid
  setsid "$(nginx_bin)" -p "$dir/nginx" -c "$dir/nginx/nginx.conf" &
  nginx_pid=$!
  pids+=("$nginx_pid")
  wait_http "http://$host:$port/lb-healthz" 30 "$nginx_pid" "nginx (see $dir/nginx/error.log)"
}

write_state() {  # CLUSTER_DIR/cluster.json, replaced whole (pids change on restarts)
  local store_json
  if [ "$store_kind" = s3 ]; then
    store_json="{\"kind\": \"s3\", \"endpoint\": \"http://$host:$s3_port\", \"bucket\": \"$s3_bucket\", \"prefix\": \"$s3_prefix\", \"dir\": \"$dir/s3\", \"pid\": $store_pid}"
  else
    store_json="{\"kind\": \"dir\", \"data\": \"$dir/data\"}"
  fi
  cat >"$dir/cluster.json.tmp" <<STATE
{"url": "http://$host:$port", "pid": $$, "balance": "$balance", "dir": "$dir",
 "nginx": {"pid": $nginx_pid, "port": $port, "conf": "$dir/nginx/nginx.conf", "access_log": "$dir/nginx/access.log", "error_log": "$dir/nginx/error.log"},
 "storage": $store_json, "env": $env_json,
 "replicas": [$replicas_json]}
STATE
  mv "$dir/cluster.json.tmp" "$dir/cluster.json"
}

# Serves until a signal arrives, restarting nginx and the S3 server when they die. A killed
# nginx master leaves its workers holding the port; its process group goes before the restart.
supervise() {
  while true; do
    sleep 0.2 &
    wait $! || true
    local restarted=""
    if [ "$store_kind" = s3 ] && ! kill -0 "$store_pid" 2>/dev/null; then
      echo "cluster: the S3 server (pid $store_pid) died; starting it again in $restart_delay s" >&2
      sleep "$restart_delay"
      start_store || { echo "cluster: the S3 server did not come back; stopping" >&2; exit 1; }
      restarted=1
    fi
    if ! kill -0 "$nginx_pid" 2>/dev/null; then
      echo "cluster: nginx (pid $nginx_pid) died; starting it again in $restart_delay s" >&2
      kill -KILL -- "-$nginx_pid" 2>/dev/null || true
      sleep "$restart_delay"
      start_nginx || { echo "cluster: nginx did not come back; stopping" >&2; exit 1; }
      restarted=1
    fi
    [ -z "$restarted" ] || write_state
  done
}

up() {
  install_nginx
  [ -x "$bin" ] || { echo "cluster: $bin not found (make build)" >&2; exit 1; }
  rm -f "$dir/cluster.json"
  # nginx's cache starts empty at every start (the data, in the store, survive).
  rm -rf "$dir/nginx/cache"
  mkdir -p "$dir/nginx" "$dir/logs"
  trap 'stop_all' EXIT
  trap 'echo; echo "cluster: stopping"; exit 0' INT TERM

  # ---- storage ----
  local store_flags=() env_json="{}"
  case "$storage" in
    dir)
      store_flags=(--data "$dir/data")
      store_kind=dir ;;
    s3)
      local key=solidtex secret=solidtex-secret
      # Go's official tarball installs to /usr/local/go; a non-login shell may not have it on PATH.
      command -v go >/dev/null || { [ -x /usr/local/go/bin/go ] && export PATH=/usr/local/go/bin:$PATH; } || true
      "$root/scripts/versitygw.sh" build >/dev/null ||
        { echo "cluster: cannot build versitygw (the S3 server); CLUSTER_STORAGE=dir runs without it" >&2; exit 1; }
      store_key=$key store_secret=$secret
      start_store || exit 1
      export AWS_ACCESS_KEY_ID=$key AWS_SECRET_ACCESS_KEY=$secret AWS_REGION=us-east-1
      store_flags=(--storage "s3://$s3_bucket/$s3_prefix" --s3-endpoint "http://$host:$s3_port")
      env_json="{\"AWS_ACCESS_KEY_ID\": \"$key\", \"AWS_SECRET_ACCESS_KEY\": \"$secret\", \"AWS_REGION\": \"us-east-1\"}" ;;
    *) echo "cluster: CLUSTER_STORAGE must be dir or s3" >&2; exit 2 ;;
  esac

  # ---- replicas ----
  local i rport argv replicas_json=""
  for i in $(seq 1 "$replicas"); do
    rport=$((port + i))
    # shellcheck disable=SC2206
    argv=("$bin" serve --host "$host" --port "$rport" "${store_flags[@]}" $serve_flags)
    "${argv[@]}" >>"$dir/logs/replica$i.log" 2>&1 &
    pids+=($!)
    replicas_json+="${replicas_json:+, }{\"url\": \"http://$host:$rport\", \"port\": $rport, \"pid\": ${pids[-1]}, \"log\": \"$dir/logs/replica$i.log\", \"argv\": $(python3 -c 'import json,sys; print(json.dumps(sys.argv[1:]))' "${argv[@]}")}"
  done
  for i in $(seq 1 "$replicas"); do
    wait_http "http://$host:$((port + i))/healthz" 60 "${pids[-$((replicas - i + 1))]}" "replica $i (see $dir/logs/replica$i.log)"
  done

  # ---- nginx ----
  render_local "$dir/nginx/nginx.conf"
  "$(nginx_bin)" -p "$dir/nginx" -c "$dir/nginx/nginx.conf" -t -q
  start_nginx || exit 1
  wait_http "http://$host:$port/healthz" 30 "$nginx_pid" "nginx's upstream"
  write_state
  cat <<MSG

solidtex cluster: $replicas replicas behind nginx ($balance), storage: $storage
  $(printf 'http://%s:%s' "$host" "$port")            <- use this URL (browser app, API)
  replicas: $(for i in $(seq 1 "$replicas"); do printf 'http://%s:%s ' "$host" "$((port + i))"; done)
  logs: $dir/logs, $dir/nginx/access.log; state: $dir/cluster.json
Ctrl-C stops the cluster; nginx and the S3 server are restarted if they die.
MSG
  supervise
}

case "${1:-up}" in
  up) up ;;
  deps) install_nginx ;;
  render) [ $# -eq 2 ] || { echo "usage: $0 render FILE" >&2; exit 2; }; render_local "$2" ;;
  k8s-configmap) k8s_configmap ;;
  *) echo "usage: $0 [up] | deps | render FILE | k8s-configmap" >&2; exit 2 ;;
esac
