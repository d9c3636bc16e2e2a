#!/usr/bin/env bash
# Soak test of tod_server's REST front end (docs/service.md#soak):
#   1. starts tod_server (--workers 2) on loopback;
#   2. measures its capacity: closed-loop tod_load with valid frames, twice as many requests in
#      flight as workers, so the workers never wait (ok responses per second);
#   3. for --duration seconds drives --load-fraction (0.8) of that capacity with valid frames
#      (open loop), plus corrupt bodies (tod_load --corrupt: truncated JPEG and PNG, noise) and
#      slow clients (bash over /dev/tcp: headers trickled, body trickled, or a body stalled at
#      1 byte/s until the server's request deadline answers 408);
#   4. samples the server's RSS (/proc/PID/status VmRSS) and a liveness probe every
#      --sample-seconds (10);
#   5. checks that no accepted request was lost: every request the server counted (REST handler
#      answers in tod_requests_total, answered transport refusals in tod_http_refused_total)
#      came back to a client, nothing is left in flight, and the server is still alive.
# Exit 0 when nothing was lost; 1 otherwise. Everything it writes goes to --out.
#
#   deploy/soak.sh --frames DIR [--duration 600] [--model models/default] [--out DIR]
#
# DIR holds the frames (.png/.jpg, searched recursively; linked, never copied), e.g. frames made
# by `build/bin/tod synth` (DIR/leftImg8bit) or a folder of real camera frames.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=$ROOT/build/bin
MODEL=$ROOT/models/default
FRAMES=""
OUT=""
DURATION=600
WORKERS=2
CAPACITY=""  # requests/s; measured when not given
CAPACITY_SECONDS=30
CAPACITY_WARMUP=5
LOAD_FRACTION=0.8
CORRUPT_SHARE=0.25  # corrupt requests per valid request
SLOW_CLIENTS=4
REQUEST_TIMEOUT=30  # the server's --http-request-timeout (its default), which stalled clients meet
SAMPLE_SECONDS=10
MAX_FRAMES=50

usage() {
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'
  cat <<EOF
Options (defaults in brackets):
  --frames DIR             frames to send (required)
  --out DIR                results: summary.txt, rss.tsv, JSON reports, logs [mktemp]
  --duration S             soak seconds [$DURATION]
  --model DIR              model bundle [models/default]
  --bin DIR                tod_server, tod_load [build/bin]
  --workers N              server workers [$WORKERS]
  --capacity R             skip the measurement, take R requests/s
  --capacity-seconds S     measuring window [$CAPACITY_SECONDS], after --capacity-warmup S [$CAPACITY_WARMUP]
  --load-fraction F        share of capacity driven with valid frames [$LOAD_FRACTION]
  --corrupt-share F        corrupt requests per valid request [$CORRUPT_SHARE]
  --slow-clients N         slow connections at any time [$SLOW_CLIENTS]
  --http-request-timeout S the server's whole-request deadline [$REQUEST_TIMEOUT]
  --sample-seconds S       RSS and liveness sampling period [$SAMPLE_SECONDS]
  --max-frames N           frames used at most [$MAX_FRAMES]
EOF
}

while (($#)); do
  case $1 in
    -h | --help)
      usage
      exit 0
      ;;
  esac
  (($# >= 2)) || {
    echo "soak: $1 needs a value (see --help)" >&2
    exit 2
  }
  case $1 in
    --frames) FRAMES=$2 ;;
    --out) OUT=$2 ;;
    --duration) DURATION=$2 ;;
    --model) MODEL=$2 ;;
    --bin) BIN=$2 ;;
    --workers) WORKERS=$2 ;;
    --capacity) CAPACITY=$2 ;;
    --capacity-seconds) CAPACITY_SECONDS=$2 ;;
    --capacity-warmup) CAPACITY_WARMUP=$2 ;;
    --load-fraction) LOAD_FRACTION=$2 ;;
    --corrupt-share) CORRUPT_SHARE=$2 ;;
    --slow-clients) SLOW_CLIENTS=$2 ;;
    --http-request-timeout) REQUEST_TIMEOUT=$2 ;;
    --sample-seconds) SAMPLE_SECONDS=$2 ;;
    --max-frames) MAX_FRAMES=$2 ;;
    *)
      echo "soak: unknown option $1 (see --help)" >&2
      exit 2
      ;;
  esac
  shift 2
done
[[ -n $FRAMES && -d $FRAMES ]] || {
  echo "soak: --frames DIR is required and must be a directory" >&2
  exit 2
}
for tool in tod_server tod_load; do
  [[ -x $BIN/$tool ]] || {
    echo "soak: $BIN/$tool not built" >&2
    exit 2
  }
done
[[ -n $OUT ]] || OUT=$(mktemp -d -t tod_soak.XXXXXX)
mkdir -p "$OUT"
rm -rf "$OUT/frames" "$OUT/slow.txt" "$OUT/rss.tsv"
mkdir -p "$OUT/frames"

# --- child processes: every one is recorded and ended on exit ------------------------------------
CHILDREN=()
SERVER_PID=""
cleanup() {
  local pid
  for pid in "${CHILDREN[@]}"; do kill "$pid" 2>/dev/null || true; done
  if [[ -n $SERVER_PID ]]; then
    kill -TERM "$SERVER_PID" 2>/dev/null || true
  fi
  wait 2>/dev/null || true
}
trap cleanup EXIT
trap 'exit 130' INT TERM

log() { printf '[soak %s] %s\n' "$(date +%T)" "$*" >&2; }
calc() { awk "BEGIN { printf \"%.3f\", $* }"; }

# --- frames: linked from DIR, never copied ---------------------------------------------------------
n=0
while IFS= read -r frame; do
  ext=${frame##*.}
  ln -s "$(cd "$(dirname "$frame")" && pwd)/$(basename "$frame")" \
    "$OUT/frames/$(printf '%04d' "$n").${ext,,}"
  n=$((n + 1))
done < <(find -L "$FRAMES" -type f \( -iname '*.png' -o -iname '*.jpg' -o -iname '*.jpeg' \) |
  sort | head -n "$MAX_FRAMES")
((n > 0)) || {
  echo "soak: no .png/.jpg frames under $FRAMES" >&2
  exit 2
}
mapfile -t FRAME_FILES < <(find "$OUT/frames" -name '*.*' | sort)
log "$n frames from $FRAMES; results in $OUT"

# --- server ----------------------------------------------------------------------------------------
free_port() {
  local port
  for _ in $(seq 100); do
    port=$((20000 + RANDOM % 40000))
    # Nothing answers a connect there: free a moment ago.
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
      echo "$port"
      return
    fi
  done
  echo "soak: no free port" >&2
  return 1
}
HTTP_PORT=$(free_port)
GRPC_PORT=$(free_port)
while [[ $GRPC_PORT == "$HTTP_PORT" ]]; do GRPC_PORT=$(free_port); done
BASE=http://127.0.0.1:$HTTP_PORT
"$BIN/tod_server" --model "$MODEL" --host 127.0.0.1 --http-port "$HTTP_PORT" \
  --grpc-port "$GRPC_PORT" --workers "$WORKERS" --http-request-timeout "$REQUEST_TIMEOUT" \
  --log-format json >"$OUT/server.log" 2>&1 &
SERVER_PID=$!
for _ in $(seq 600); do
  curl -sf -o /dev/null --max-time 2 "$BASE/v2/health/ready" && break
  kill -0 "$SERVER_PID" 2>/dev/null || {
    echo "soak: tod_server exited; see $OUT/server.log" >&2
    exit 1
  }
  sleep 0.2
done
curl -sf -o /dev/null --max-time 2 "$BASE/v2/health/ready" || {
  echo "soak: tod_server not ready after 120 s" >&2
  exit 1
}
log "tod_server pid $SERVER_PID on $BASE, --workers $WORKERS"

scrape() { curl -sf --max-time 30 "$BASE/metrics"; }
# Sum of the samples of a family whose labels contain FILTER (a regex), in a scrape on stdin.
metric_sum() {
  awk -v name="$1" -v filter="$2" '
    index($0, name "{") == 1 || index($0, name " ") == 1 {
      if ($0 ~ filter) sum += $NF
    }
    END { printf "%d", sum }'
}
# Requests the server answered or must answer: REST handler answers plus the transport's answered
# refusals (idle, write and TLS timeouts have no answer).
server_answerable() {
  local text
  text=$(scrape)
  echo $(($(metric_sum tod_requests_total 'protocol="http"' <<<"$text") + \
    $(metric_sum tod_http_refused_total '.' <<<"$text") - \
    $(metric_sum tod_http_refused_total 'reason="(idle_timeout|write_timeout|tls_handshake)"' \
      <<<"$text")))
}
json_number() { grep -o "\"$2\": *[-0-9.e+]*" "$1" | head -n 1 | sed 's/.*: *//'; }

# --- capacity --------------------------------------------------------------------------------------
if [[ -z $CAPACITY ]]; then
  log "measuring capacity: closed loop, $((2 * WORKERS)) in flight, ${CAPACITY_SECONDS} s"
  "$BIN/tod_load" --addr "127.0.0.1:$HTTP_PORT" --http --images "$OUT/frames" \
    --concurrency $((2 * WORKERS)) --warmup "$CAPACITY_WARMUP" --duration "$CAPACITY_SECONDS" \
    --timeout-ms 120000 --json "$OUT/capacity.json" >"$OUT/capacity.txt"
  CAPACITY=$(json_number "$OUT/capacity.json" ok_throughput_rps)
fi
CAPACITY=$(calc "$CAPACITY")
VALID_RATE=$(calc "$CAPACITY * $LOAD_FRACTION")
CORRUPT_RATE=$(calc "$VALID_RATE * $CORRUPT_SHARE")
# tod_load takes --rate 0 for a closed loop: both rates must be positive.
awk "BEGIN { exit !($VALID_RATE >= 0.001 && $CORRUPT_RATE >= 0.001) }" || {
  echo "soak: capacity $CAPACITY requests/s gives rates $VALID_RATE and $CORRUPT_RATE/s" >&2
  exit 1
}
log "capacity $CAPACITY requests/s: valid $VALID_RATE/s, corrupt $CORRUPT_RATE/s," \
  "$SLOW_CLIENTS slow clients, for $DURATION s"

# --- slow clients ----------------------------------------------------------------------------------
# The status code of the answer on fd 3 within $1 seconds, or "none".
read_status() {
  local line=""
  if IFS= read -r -t "$1" line <&3 && [[ $line =~ ^HTTP/1\.[01]\ ([0-9]{3}) ]]; then
    echo "${BASH_REMATCH[1]}"
  else
    echo none
  fi
}
# One request on a new connection, sent slowly as KIND:
#   slow_headers  the header one line at a time, then the body;
#   slow_body     the header, then the body in 8 pieces;
#   stalled       the header, then one body byte a second until the server answers (408).
# The body is the first half of a frame: a truncated image, refused with 400 once it has arrived.
# So the slow clients hold connections, buffers and I/O, not the workers, whose load stays the
# valid frames' share of capacity. The slow ones pause 1/32 of the request deadline between pieces
# (a quarter of it in all: answered, not refused, even on a busy machine). Appends "KIND STATUS"
# to slow.txt.
slow_request() {
  local kind=$1 frame=$2 type=image/png size pause status=none
  [[ $frame == *.jp*g ]] && type=image/jpeg
  size=$(($(stat -L -c %s "$frame") / 2))
  pause=$(calc "$REQUEST_TIMEOUT / 32")
  if exec 3<>"/dev/tcp/127.0.0.1/$HTTP_PORT"; then
    local head=("POST /v1/detect?map=none HTTP/1.1" "Host: soak" "Content-Type: $type"
      "Content-Length: $size" "X-Soak: $kind" "X-Soak-Pad-1: slow" "X-Soak-Pad-2: slow" "")
    case $kind in
      slow_headers)
        local line
        for line in "${head[@]}"; do
          printf '%s\r\n' "$line" >&3 || break
          sleep "$pause"
        done
        head -c "$size" "$frame" >&3 || true
        status=$(read_status 300)
        ;;
      slow_body)
        local piece=$(((size + 7) / 8)) offset
        printf '%s\r\n' "${head[@]}" >&3 || true
        for ((offset = 0; offset < size; offset += piece)); do
          dd if="$frame" iflag=skip_bytes,count_bytes skip="$offset" \
            count=$((offset + piece < size ? piece : size - offset)) status=none >&3 || break
          sleep "$pause"
        done
        status=$(read_status 300)
        ;;
      stalled)
        printf '%s\r\n' "${head[@]}" >&3 || true
        local second rc part answer=""
        for ((second = 0; second < 2 * REQUEST_TIMEOUT + 30; second++)); do
          rc=0
          part=""
          # The 1 s wait; a read that times out mid-line keeps what it read in `part`.
          IFS= read -r -t 1 part <&3 || rc=$?
          answer+=$part
          ((rc > 128)) || break # the whole status line (or EOF): no more waiting
          [[ -n $answer ]] || printf x >&3 2>/dev/null || true
        done
        [[ $answer =~ ^HTTP/1\.[01]\ ([0-9]{3}) ]] && status=${BASH_REMATCH[1]}
        ;;
    esac
    exec 3>&-
  fi
  echo "$kind $status" >>"$OUT/slow.txt"
}
# Slow client I: kinds in turn (starting at I), frames in turn, until END.
slow_client() {
  local i=$1 round=0 kinds=(slow_headers slow_body stalled)
  trap '' PIPE # a write the server no longer reads fails instead of killing the client
  while (($(date +%s) < END)); do
    slow_request "${kinds[$(((i + round) % 3))]}" \
      "${FRAME_FILES[$(((i + round) % ${#FRAME_FILES[@]}))]}"
    round=$((round + 1))
  done
}

# --- sampler: RSS and liveness every SAMPLE_SECONDS ------------------------------------------------
sample() {
  local rss live
  rss=$(awk '/^VmRSS:/ { print $2 }' "/proc/$SERVER_PID/status" 2>/dev/null || echo 0)
  live=$(curl -s -o /dev/null -w '%{http_code}' --max-time 10 "$BASE/v2/health/live" || true)
  printf '%s\t%s\t%s\n' "$(($(date +%s) - START))" "${rss:-0}" "$live" >>"$OUT/rss.tsv"
}
sampler() {
  while (($(date +%s) < END)); do
    sleep "$SAMPLE_SECONDS"
    sample
  done
}

# --- soak ------------------------------------------------------------------------------------------
BEFORE=$(server_answerable)
START=$(date +%s)
END=$((START + DURATION))
printf 'seconds\trss_kb\tlive\n' >"$OUT/rss.tsv"
sample
"$BIN/tod_load" --addr "127.0.0.1:$HTTP_PORT" --http --images "$OUT/frames" \
  --rate "$VALID_RATE" --concurrency 32 --warmup 0 --duration "$DURATION" --timeout-ms 120000 \
  --json "$OUT/valid.json" >"$OUT/valid.txt" 2>&1 &
VALID_PID=$!
CHILDREN+=("$VALID_PID")
"$BIN/tod_load" --addr "127.0.0.1:$HTTP_PORT" --http --images "$OUT/frames" --corrupt \
  --rate "$CORRUPT_RATE" --concurrency 8 --warmup 0 --duration "$DURATION" --timeout-ms 120000 \
  --json "$OUT/corrupt.json" >"$OUT/corrupt.txt" 2>&1 &
CORRUPT_PID=$!
CHILDREN+=("$CORRUPT_PID")
SLOW_PIDS=()
for ((i = 0; i < SLOW_CLIENTS; i++)); do
  slow_client "$i" 2>>"$OUT/slow.log" & # writes cut short by the server complain there
  SLOW_PIDS+=($!)
  CHILDREN+=($!)
done
sampler &
SAMPLER_PID=$!
CHILDREN+=("$SAMPLER_PID")

failed=0
wait "$VALID_PID" || {
  log "tod_load (valid) failed: $(tail -n 3 "$OUT/valid.txt")"
  failed=1
}
wait "$CORRUPT_PID" || {
  log "tod_load (corrupt) failed: $(tail -n 3 "$OUT/corrupt.txt")"
  failed=1
}
for pid in "${SLOW_PIDS[@]}"; do wait "$pid" || failed=1; done
wait "$SAMPLER_PID" || true
CHILDREN=() # all waited for
sample      # the end, after every client is done

# --- accounting ------------------------------------------------------------------------------------
alive=yes
kill -0 "$SERVER_PID" 2>/dev/null || alive=no
FINAL=$(scrape || true)
AFTER=$(server_answerable || echo 0)
IN_FLIGHT=$(metric_sum tod_in_flight_requests '.' <<<"$FINAL")
# "KIND CODE COUNT" lines: tod_load's codes per JSON report, the slow clients' from slow.txt.
codes_of() {
  awk -v kind="$1" '
    /"codes": \{\}/ { exit }
    /"codes": \{/ { inside = 1; next }
    inside && /\}/ { exit }
    inside {
      sub(/^ *"/, ""); sub(/,$/, "")
      split($0, part, "\": ")
      gsub(/ /, "_", part[1])
      print kind, part[1], part[2]
    }' "$2"
}
{
  codes_of valid "$OUT/valid.json"
  codes_of corrupt "$OUT/corrupt.json"
  [[ -f $OUT/slow.txt ]] && sort "$OUT/slow.txt" | uniq -c | awk '{ print $2, $3, $1 }'
} >"$OUT/counts.txt"
ANSWERED=$(awk '$2 ~ /^[0-9]+$/ { n += $3 } END { printf "%d", n }' "$OUT/counts.txt")
UNANSWERED=$(awk '$2 !~ /^[0-9]+$/ { n += $3 } END { printf "%d", n }' "$OUT/counts.txt")
ACCEPTED=$((AFTER - BEFORE))
LOST=$((ACCEPTED - ANSWERED))
read -r RSS_START RSS_MIN RSS_MAX RSS_END < <(awk 'NR > 1 {
    if (n == 0 || $2 < min) min = $2; if ($2 > max) max = $2; if (n == 0) first = $2; last = $2; n++ }
  END { printf "%d %d %d %d\n", first / 1024, min / 1024, max / 1024, last / 1024 }' "$OUT/rss.tsv")
PROBES_FAILED=$(awk 'NR > 1 && $3 != 200 { n++ } END { printf "%d", n }' "$OUT/rss.tsv")

{
  echo "soak: tod_server --workers $WORKERS, model $(basename "$MODEL"), $n frames from $FRAMES"
  echo "capacity: $CAPACITY requests/s (valid frames, closed loop, $((2 * WORKERS)) in flight)"
  echo "load: $DURATION s; valid $VALID_RATE/s ($LOAD_FRACTION of capacity), corrupt $CORRUPT_RATE/s," \
    "$SLOW_CLIENTS slow clients (request deadline $REQUEST_TIMEOUT s)"
  echo "rss MB (every $SAMPLE_SECONDS s): start $RSS_START, min $RSS_MIN, max $RSS_MAX, end $RSS_END"
  echo "rss MB samples: $(awk 'NR > 1 { printf "%s%d", sep, $2 / 1024; sep = " " }' "$OUT/rss.tsv")"
  echo "liveness probes failed: $PROBES_FAILED of $(($(wc -l <"$OUT/rss.tsv") - 1))"
  echo "counts (kind status count):"
  sed 's/^/  /' "$OUT/counts.txt"
  echo "server accepted (REST answers + answered refusals): $ACCEPTED; clients got answers: $ANSWERED;" \
    "no answer at the client: $UNANSWERED"
  echo "in flight at the end: ${IN_FLIGHT:-?}; server alive: $alive"
  echo "lost accepted requests: $LOST"
} | tee "$OUT/summary.txt"

if ((failed != 0 || LOST != 0 || UNANSWERED != 0 || PROBES_FAILED != 0)) ||
  [[ $alive != yes || $IN_FLIGHT != 0 ]]; then
  echo "soak: FAILED (see $OUT)" >&2
  exit 1
fi
echo "soak: ok ($OUT)" >&2
