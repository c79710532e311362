# Sourced by the shell tests that start effectd with --port 0 and its log on stderr:
# `wait_for_port LOG` waits for the start-up line that says it listens and sets $port; the test
# fails (the log printed) when none comes within 5 s.
wait_for_port() {
  for _ in $(seq 100); do grep -q '"listening"' "$1" && break; sleep 0.05; done
  port=$(grep -o '"port":[0-9]*' "$1" | head -1 | cut -d: -f2)
  [ -n "$port" ] || { cat "$1"; echo "FAIL effectd did not listen"; exit 1; }
}
