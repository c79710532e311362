// Debian's chromium, headless, with WebGL2 on SwiftShader (the GPU-less machines these tests run
// on), for the page scripts that draw.
import puppeteer from 'puppeteer-core';

export function launchWebGl2Chromium(executablePath) {
  return puppeteer.launch({
    executablePath,
    headless: true,
    args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
           '--ignore-gpu-blocklist'],
  });
}
