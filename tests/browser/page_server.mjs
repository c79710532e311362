// The test pages' origin: one page (an import map for three, its addons and Babylon.js, and the
// canvases the script names), /page_helpers.mjs, and the engines' ES modules from node_modules
// under /nm/, as a page would load them; `files` maps more paths to files (ES modules). Returns
// { origin, close }.
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const modules = path.join(here, 'node_modules');

export async function servePages(title, canvases, files = {}) {
  const pages = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://x');
    const file = url.pathname === '/page_helpers.mjs' ? path.join(here, 'page_helpers.mjs') : files[url.pathname];
    if (file) {
      res.writeHead(200, { 'Content-Type': 'text/javascript' });
      return res.end(fs.readFileSync(file));
    }
    if (url.pathname.startsWith('/nm/')) {
      const file = path.normalize(path.join(modules, decodeURIComponent(url.pathname.slice('/nm/'.length))));
      if (!file.startsWith(modules) || !fs.existsSync(file) || !fs.statSync(file).isFile()) return res.writeHead(404).end();
      res.writeHead(200, { 'Content-Type': 'text/javascript', 'Access-Control-Allow-Origin': '*' });  // modules for other origins' pages too
      return res.end(fs.readFileSync(file));
    }
    res.writeHead(200, { 'Content-Type': 'text/html' });
    res.end(`<!doctype html><title>${title}</title>` +
            '<script type="importmap">{"imports":{"three":"/nm/three/build/three.module.js",' +
            '"three/addons/":"/nm/three/examples/jsm/","@babylonjs/core/":"/nm/@babylonjs/core/",' +
            '"@babylonjs/loaders/":"/nm/@babylonjs/loaders/"}}</script>' +
            canvases.map((id) => `<canvas id="${id}"></canvas>`).join(''));
  });
  await new Promise((r) => pages.listen(0, '127.0.0.1', r));
  return { origin: `http://localhost:${pages.address().port}`, close: () => pages.close() };
}
