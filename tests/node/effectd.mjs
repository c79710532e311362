// What the node test scripts share: start an effectd binary on an ephemeral port, and a
// check() that prints ok/FAIL lines and counts failures.
import { spawn } from 'node:child_process';

// Starts `binary` with `args` on 127.0.0.1:0; resolves to { url, process } once it listens.
export async function startEffectd(binary, args = []) {
  const server = spawn(binary, ['--host', '127.0.0.1', '--port', '0', ...args], { stdio: ['ignore', 'ignore', 'pipe'] });
  const url = await new Promise((resolve, reject) => {
    let log = '';
    server.stderr.on('data', (d) => {
      log += d;
      const m = log.match(/"listening"[^\n]*"port":(\d+)/) || log.match(/"port":(\d+)[^\n]*"listening"/);
      if (m) resolve(`http://127.0.0.1:${m[1]}`);
    });
    server.on('exit', (code) => reject(new Error(`effectd exited (${code}): ${log}`)));
    setTimeout(() => reject(new Error(`effectd did not start: ${log}`)), 10000);
  });
  server.stderr.resume();
  return { url, process: server };
}

export const results = { failures: 0 };
export function check(ok, what, detail) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}${ok || detail === undefined ? '' : ': ' + JSON.stringify(detail)}`);
  if (!ok) results.failures++;
  return ok;
}
