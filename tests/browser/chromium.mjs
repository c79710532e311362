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

// A new page that prints the page's console and errors, at `url`.
export async function openLoggedPage(browser, url) {
  const page = await browser.newPage();
  page.on('console', (m) => console.log(`  page: ${m.text()}`));
  page.on('pageerror', (e) => console.log(`  page error: ${e.message}`));
  await page.goto(url);
  return page;
}
