// A typed client generated from proto/openapi.yaml (openapi-typescript -> generated/), type-
// checked by tsc --strict and then run against the server: every route, with bodies and
// answers typed by the contract. A contract that cannot type this client fails to compile.
import type { paths } from './generated/effectd-api';

type PostPath = { [P in keyof paths]: paths[P] extends { post: object } ? P : never }[keyof paths];
type RequestOf<P extends PostPath> = paths[P]['post'] extends { requestBody: { content: { 'application/json': infer B } } } ? B : never;
type AnswerOf<P extends PostPath> = paths[P]['post'] extends { responses: { 200: { content: { 'application/json': infer A } } } } ? A : never;
type Problem = paths['/v1/fog']['post']['responses'][400]['content']['application/problem+json'];

declare const process: { argv: string[]; exit(code: number): never };  // node's, without @types/node
const base = process.argv[2] ?? '';
let failures = 0;
function check(ok: boolean, what: string): void {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures++;
}

async function post<P extends PostPath>(path: P, body: RequestOf<P>): Promise<{ status: number; answer: AnswerOf<P>; bytes: ArrayBuffer }> {
  const res = await fetch(base + path, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
  const bytes = await res.arrayBuffer();
  const json = res.headers.get('Content-Type')?.includes('json') ? JSON.parse(new TextDecoder().decode(bytes)) : undefined;
  return { status: res.status, answer: json as AnswerOf<P>, bytes };
}

async function main(): Promise<void> {
  const health = (await (await fetch(`${base}/healthz`)).json()) as paths['/healthz']['get']['responses'][200]['content']['application/json'];
  check(health.status === 'ok', 'GET /healthz');
  const ready = (await (await fetch(`${base}/readyz`)).json()) as paths['/readyz']['get']['responses'][200]['content']['application/json'];
  check(ready.status === 'ready' && typeof ready.components === 'object', 'GET /readyz');
  check((await (await fetch(`${base}/metrics`)).text()).includes('# TYPE'), 'GET /metrics');
  check((await (await fetch(`${base}/v1/openapi.yaml`)).text()).startsWith('openapi: 3.1'), 'GET /v1/openapi.yaml');
  check((await fetch(`${base}/v1/schemas/fog-answer.json`)).status === 200, 'GET /v1/schemas/{name}');

  const fog = await post('/v1/fog', { fog: { fogType: 'DISTANCE_EXP2', color: [0.8, 0.8, 0.8], distanceCoefficient: 0.07 },
                                      table: { size: 64, encoding: 'json' }, include: ['table', 'stats'] });
  check(fog.status === 200 && (fog.answer.table?.factor?.length ?? 0) === 64 && fog.answer.error!.maxError < 0.01, 'POST /v1/fog: 64 factors, error < 0.01');

  const bolt = await post('/v1/lightning', { grid: { width: 64, height: 64 }, start: [32, 0], targets: [[32, 63]],
                                             method: 'fast', include: ['polylines', 'fractalDimension'] });
  const main0 = bolt.answer.polylines?.[0];
  check(bolt.status === 200 && main0?.channel === 'main' && main0.points.length === 2 * main0.step.length, 'POST /v1/lightning: main channel first');

  const quad = await post('/v1/tangents', { mesh: { positions: [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0], uvs: [0, 0, 1, 0, 1, 1, 0, 1],
                                                    indices: [0, 1, 2, 0, 2, 3] }, mode: 'mikktspace', include: ['tangents'] });
  check(quad.status === 200 && quad.answer.tangents?.[0] === 1 && quad.answer.vertexCount === 4, 'POST /v1/tangents: +x tangent');

  const bubble = await post('/v1/bubble', { time: 1, features: { wobble: false }, include: ['uniforms', 'shader'] });
  check(bubble.status === 200 && (bubble.answer.shader?.vertex.startsWith('#version 300 es') ?? false), 'POST /v1/bubble: GLSL ES 3.00');

  const scene = await post('/v1/scene', { fog: { fog: { fogType: 'GL_EXP', density: 0.1 } } });
  check(scene.status === 200 && scene.answer.fog?.method === 'table-GL_EXP' && scene.answer.lightning === undefined, 'POST /v1/scene: only fog');

  const png = await post('/v1/render', { width: 32, height: 32, background: { color: [0.1, 0.2, 0.3, 1] } });
  check(png.status === 200 && new Uint8Array(png.bytes)[1] === 0x50, 'POST /v1/render: a PNG');

  const bad = await fetch(`${base}/v1/fog`, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{"fog": 1}' });
  const problem = (await bad.json()) as Problem;
  check(bad.status === 400 && problem.errors[0]?.pointer === '/fog', 'a problem names its field');
}

main().then(() => {
  console.log(failures ? `${failures} client check(s) failed` : 'typed client ok');
  process.exit(failures ? 1 : 0);
});
