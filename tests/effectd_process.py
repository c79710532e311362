"""Starting an effectd binary for a test, benchmark or script that talks to it over HTTP: on
any free port, found in its '"listening"' log line. Used by tests/memory_test.py,
tests/schema_truth_test.py, scripts/same-answers.py and bench/*.py."""
import re
import subprocess
import threading

LISTENING = re.compile(r'"listening".*"port":(\d+)')


def start(binary, *flags):
    """Starts `binary --port 0 FLAGS...` with its stderr piped; returns (process, port) once it
    listens. Exits (SystemExit) when the binary ends its stderr without listening. The rest of
    its stderr (the access log) is read and dropped, so a long run never fills the pipe."""
    p = subprocess.Popen([binary, "--port", "0", *flags], stderr=subprocess.PIPE, text=True)
    for line in iter(p.stderr.readline, ""):
        m = LISTENING.search(line)
        if m:
            threading.Thread(target=lambda: [None for _ in p.stderr], daemon=True).start()
            return p, int(m.group(1))
    p.wait()
    raise SystemExit(f"{binary} did not start")
