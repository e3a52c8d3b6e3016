// The `avs view` page in a real browser (issue 17): headless Chromium (Debian's, driven by
// puppeteer-core) opens http://HOST:PORT/ while a graph runs, waits until the page has drawn
// depth frames and poses, checks that the depth canvas is not blank (most pixels coloured,
// both ends of the colour map present), that the pose readout changes, that every panel drew
// what the graph published (target centroid, pose error against /sim/ground_truth, torques,
// stage times, the 3-D view of scene and model through Chromium's software WebGL, the time
// plots, /diagnostics), and saves a screenshot. Waits are for conditions, with generous
// timeouts.
// AVS_PAGE_EXPECT says what runs: "publisher" (default: view_test_publisher, whose values
// are known exactly) or "demo" (`avs demo --view`: the lockstep closed loop of the ken, values
// checked for form and plausibility).
// usage: node check_page.mjs http://127.0.0.1:PORT/ SCREENSHOT.png [JOINT_STATES]
// (JOINT_STATES: joint states the page must have drawn before the screenshot, default 200.)
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const puppeteer = require("puppeteer-core");

const [url, screenshot, jointStates = "200"] = process.argv.slice(2);
const TIMEOUT_MS = 60000;
const chromium = process.env.AVS_CHROMIUM ?? "/usr/bin/chromium";

async function main() {
  const browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    // Root in a container: no sandbox; no GPU on the test machines; a small /dev/shm.
    // WebGL (the 3-D panel) through SwiftShader, the software renderer.
    args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--enable-unsafe-swiftshader",
      "--window-size=1280,1400"],
    defaultViewport: { width: 1280, height: 1400 },
    protocolTimeout: 20 * TIMEOUT_MS,
  });
  let failures = 0;
  const check = (ok, what) => {
    if (!ok) {
      failures++;
      console.error(`FAILED: ${what}`);
    }
  };
  try {
    const page = await browser.newPage();
    page.on("console", (m) => console.log(`page: ${m.text()}`));
    page.on("pageerror", (e) => {
      failures++;
      console.error(`FAILED: page error: ${e.message}`);
    });
    await page.goto(url, { waitUntil: "load", timeout: TIMEOUT_MS });
    await page.waitForFunction(
      () => window.avsView && window.avsView.depthFrames >= 3 && window.avsView.poseCount >= 10 &&
        window.avsView.jointCount >= 10,
      { timeout: TIMEOUT_MS, polling: 100 },
    );
    const pixels = await page.evaluate(() => {
      const c = document.getElementById("depth");
      const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
      let coloured = 0, red = 0, blue = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (d[i] + d[i + 1] + d[i + 2] > 0) coloured++;
        if (d[i] > 200 && d[i + 2] < 60) red++;
        if (d[i + 2] > 200 && d[i] < 60) blue++;
      }
      return { total: d.length / 4, coloured, red, blue };
    });
    console.log(`depth canvas: ${JSON.stringify(pixels)}`);
    check(pixels.coloured > 0.9 * pixels.total, "the depth canvas is not blank");
    check(pixels.red > 0 && pixels.blue > 0, "near (red) and far (blue) both drawn");

    // The other panels.
    const expect = process.env.AVS_PAGE_EXPECT ?? "publisher";
    check(["publisher", "demo"].includes(expect), `AVS_PAGE_EXPECT=${expect} is known`);
    const exact = expect === "publisher";
    await page.waitForFunction(
      () => window.avsView.targetCount >= 3 && window.avsView.torqueCount >= 3 &&
        window.avsView.errorCount >= 3 && window.avsView.timingCount >= 3 &&
        window.avsView.sceneClouds >= 2 && window.avsView.modelClouds >= 2,
      { timeout: TIMEOUT_MS, polling: 100 },
    );
    const text = (id) => page.$eval(id, (e) => e.textContent);
    const target = await text("#target-readout");
    const error = await text("#error-readout");
    const timings = await text("#timings");
    console.log(`target: ${target}\nerror: ${error}\ntimings:\n${timings}`);
    if (exact) {
      check(/^centroid \(\d+\.0, \d+\.0\) px, mean depth 1\.250 m$/.test(target), "the centroid readout");
      // The publisher's truth is the pose moved by 2 mm in x, same orientation.
      check(error.includes("position 2.00 mm, orientation 0.00 deg"), "the pose error readout");
      check(timings.includes("decode     median 0.750 ms  max 0.750 ms") &&
        timings.includes("matching   median 0.500 ms"), "the stage times");
    } else {
      // The ken at about 1 m (launch_config/scenes/manipulator_ken.yaml), compared with its
      // own truth (?object=ken from the demo's address), every stage of the loop timed.
      const centroid = /^centroid \((\d+\.\d), (\d+\.\d)\) px, mean depth (\d+\.\d{3}) m$/.exec(target);
      check(centroid && Number(centroid[3]) > 0.5 && Number(centroid[3]) < 2.5, "the centroid readout");
      check(/^error against \/sim\/ground_truth of ken: position \d+\.\d\d mm, orientation \d+\.\d\d deg$/
        .test(error), "the pose error readout names the object and gives both errors");
      for (const stage of ["decode", "matching", "tracking"]) {
        check(new RegExp(`^${stage} +median \\d+\\.\\d{3} ms`, "m").test(timings), `the ${stage} stage time`);
      }
    }
    const green = await page.evaluate(() => {
      const c = document.getElementById("depth");
      const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
      let n = 0;
      for (let i = 0; i < d.length; i += 4) if (d[i + 1] > 200 && d[i] < 60 && d[i + 2] < 60) n++;
      return n;
    });
    check(green > 0, `the centroid marked on the depth map (${green} green pixels)`);
    const webgl = await page.evaluate(() => window.avsView.webgl);
    check(webgl, "WebGL for the 3-D view");
    if (webgl) {
      const drawn = await page.evaluate(() => {
        const src = document.getElementById("scene3d");
        const c = document.createElement("canvas");
        c.width = src.width;
        c.height = src.height;
        const ctx = c.getContext("2d");
        ctx.drawImage(src, 0, 0);
        const d = ctx.getImageData(0, 0, c.width, c.height).data;
        let grey = 0, red = 0;
        for (let i = 0; i < d.length; i += 4) {
          if (d[i] > 120 && Math.abs(d[i] - d[i + 1]) < 20 && Math.abs(d[i] - d[i + 2]) < 20) grey++;
          if (d[i] > 200 && d[i + 1] < 90 && d[i + 2] < 90) red++;
        }
        return { grey, red };
      });
      console.log(`3-D canvas: ${JSON.stringify(drawn)}`);
      check(drawn.grey > 20 && drawn.red > 20, "the 3-D view shows scene points (grey) and the model (red)");
    }
    const first = await page.$eval("#pose-readout", (e) => e.textContent);
    await page.waitForFunction(
      (before) => document.getElementById("pose-readout").textContent !== before,
      { timeout: TIMEOUT_MS, polling: 100 },
      first,
    );
    const second = await page.$eval("#pose-readout", (e) => e.textContent);
    console.log(`pose readout changed:\n${first}\n->\n${second}`);
    check(second.includes("camera_optical_frame"), "the pose readout names its frame");
    // Let the plots fill a little before the picture.
    await page.waitForFunction((n) => window.avsView.jointCount >= n, { timeout: 5 * TIMEOUT_MS },
      Number(jointStates));
    // The time plots (uPlot): each drew coloured lines on its canvas.
    const lines = await page.evaluate(() =>
      ["pose-plot", "error-plot", "joint-plot", "torque-plot"].map((id) => {
        const c = document.querySelector(`#${id} canvas`);
        if (!c) return [id, -1];
        const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4) {
          if (Math.max(d[i], d[i + 1], d[i + 2]) - Math.min(d[i], d[i + 1], d[i + 2]) > 100) n++;
        }
        return [id, n];
      }));
    console.log(`plot line pixels: ${JSON.stringify(lines)}`);
    for (const [id, n] of lines) check(n > 50, `the ${id} drew its lines (${n} coloured pixels)`);
    // /diagnostics with the container's figures for each component (the first report may
    // come before the components are active).
    const figures = /: active \(\d+\.\d Hz, mean \d+\.\d{3} ms, max \d+\.\d{3} ms\)/;
    const shown = await page.waitForFunction(
      (re) => new RegExp(re).test(document.getElementById("diagnostics").textContent),
      { timeout: TIMEOUT_MS, polling: 100 }, figures.source).then(() => true, () => false);
    const diagnostics = await page.$eval("#diagnostics", (e) => e.textContent);
    console.log(`diagnostics:\n${diagnostics}`);
    check(shown, "the diagnostics panel gives each component's rate and callback times");
    await page.screenshot({ path: screenshot });
    console.log(`screenshot: ${screenshot}`);
  } finally {
    await browser.close();
  }
  console.log(failures === 0 ? "page check: all passed" : `page check: ${failures} failures`);
  process.exit(failures === 0 ? 0 : 1);
}

main().catch((e) => {
  console.error(`FAILED: ${e.message}`);
  process.exit(1);
});
