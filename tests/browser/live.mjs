// End-to-end test of `posecov live` in headless Chromium (Debian's `chromium`), driven by
// playwright-core. Usage: node live.mjs CONTROL_PAGE_URL [SCREENSHOT.png]
//
// Opens the control page, drags the heading σ slider of camera_on_robot with the mouse,
// waits until the page reports the new change's final picture as sent, clicks Save when
// the page offers it, reads the methods offered and the status line, clears the typed field
// (refused, naming it), narrows the window to 800 px (the layout stacks), and prints one JSON
// line {"id", "value", "generation", "saved", "methods", "statusText", "emptyError", "narrow"} for the
// Rust side (tests/live_browser.rs), which
// checks on the viewer's gRPC stream that the new data arrived.
import { chromium } from "playwright-core";
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

const [url, screenshot] = process.argv.slice(2);
if (!url) {
  console.error("usage: node live.mjs CONTROL_PAGE_URL [SCREENSHOT.png]");
  process.exit(2);
}
const ID = "pose[0].cov.std_deg[2]";
const profile = mkdtempSync(join(tmpdir(), "posecov-chromium-"));
// A fresh profile directory (playwright passes it as --user-data-dir).
const browser = await chromium.launchPersistentContext(profile, {
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  headless: true,
  viewport: { width: 1400, height: 860 },
  args: [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
  ],
});
let code = 1;
try {
  const page = browser.pages()[0] || await browser.newPage();
  // The control page's own errors; the embedded viewer's (e.g. fetches it makes to the
  // internet, which a sandbox refuses) are not the page's and are left out.
  const origin = new URL(url).origin;
  page.on("console", (m) => {
    if (m.type() === "error" && (m.location().url || "").startsWith(origin)) console.error("page:", m.text(), m.location().url);
  });
  await page.goto(url);
  const slider = page.locator(`input[type=range][data-id="${ID}"]`);
  await slider.waitFor({ timeout: 30000 });
  const status = page.locator("#status");
  await page.waitForFunction(() => document.getElementById("status").dataset.done === "true", null, { timeout: 60000 });
  const before = Number(await slider.inputValue());
  // Drag the thumb from its place to 55 % of the track with the mouse, as a user would.
  const box = await slider.boundingBox();
  const min = Number(await slider.getAttribute("min"));
  const max = Number(await slider.getAttribute("max"));
  const x0 = box.x + box.width * ((before - min) / (max - min));
  const y = box.y + box.height / 2;
  await page.mouse.move(x0, y);
  await page.mouse.down();
  for (let i = 1; i <= 10; i++) await page.mouse.move(x0 + (box.x + 0.55 * box.width - x0) * (i / 10), y);
  await page.mouse.up();
  const after = Number(await slider.inputValue());
  if (!(after > before)) throw new Error(`the slider did not move: ${before} → ${after}`);
  // The page shows the newest generation's final picture as sent.
  await page.waitForFunction(() => {
    const s = document.getElementById("status").dataset;
    return s.done === "true" && s.shown !== "" && s.shown === s.generation && Number(s.generation) >= 1;
  }, null, { timeout: 60000 });
  const typed = Number(await page.locator(`input[type=number][data-id="${ID}"]`).inputValue());
  if (Math.abs(typed - after) > 1e-9) throw new Error(`typed value ${typed} does not follow the slider ${after}`);
  const generation = Number(await status.getAttribute("data-generation"));
  // The status line as the user reads it after the change, before Save writes "saved PATH"
  // over it (until the next poll): read here, not after Save.
  const statusText = await status.textContent();
  // "Save" (shown with --save-scenario) writes the current scenario to that file.
  let saved = null;
  if (await page.locator("#save").isVisible()) {
    const [response] = await Promise.all([
      page.waitForResponse((r) => r.url().endsWith("/api/save")),
      page.click("#save"),
    ]);
    if (!response.ok()) throw new Error(`save failed: ${await response.text()}`);
    saved = (await response.json()).saved;
  }
  if (screenshot) {
    await page.waitForTimeout(3000);
    await page.screenshot({ path: screenshot });
  }
  // Only the methods that apply are offered (camera_on_robot: no closed form).
  const methods = await page.$$eval("input[type=checkbox][data-id^='scenario.methods.']",
    (boxes) => boxes.map((b) => b.dataset.id.replace("scenario.methods.", "")));
  // A cleared field is refused with a message naming it; the last good picture stays.
  const number = page.locator(`input[type=number][data-id="${ID}"]`);
  await number.fill("");
  await number.press("Enter");
  await page.locator("#error").waitFor({ state: "visible", timeout: 10000 });
  const emptyError = await page.locator("#error").textContent();
  // Under 900 px the controls stack above the viewer, each the page's width.
  await page.setViewportSize({ width: 800, height: 1000 });
  await page.waitForTimeout(300);
  const boxOf = async (sel) => page.locator(sel).boundingBox();
  const narrow = { panel: await boxOf("#panel"), viewer: await boxOf("#viewer") };
  if (screenshot) await page.screenshot({ path: screenshot.replace(/\.png$/, "") + "-narrow.png", fullPage: true });
  console.log(JSON.stringify({ id: ID, value: after, generation, saved, methods, statusText, emptyError, narrow }));
  code = 0;
} catch (e) {
  console.error(String(e && e.stack || e));
} finally {
  await browser.close();
  rmSync(profile, { recursive: true, force: true });
}
process.exit(code);
