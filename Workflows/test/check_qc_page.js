// The QC page in Debian's headless Chromium, driven by Playwright as a user
// would use it. Prints one line per check and exits 1 if any failed.
//
//   node check_qc_page.js cohort PAGE SCREENSHOT  the workflow's page: no script error, rows sort,
//       ratings persist across a reload and export as TSV, and the first interactive view
//       draws the image, the labelmap overlay and the surface (pixels counted in its screenshot)
//   node check_qc_page.js scale PAGE ROWS          a generated page: every row, no script error,
//       sorting works; its load and sort times are printed, not asserted
//
// Needs NODE_PATH with playwright-core (./run test installs it into build/test-npm).
const fs = require("fs");
const { chromium } = require("playwright-core");

const CHROMIUM = "/usr/lib/chromium/chromium";  // Debian's binary; /usr/bin/chromium is a wrapper script
let failures = 0;
function check(name, ok, detail) {
  console.log(`${ok ? "ok" : "FAILED"}: ${name}${ok || detail === undefined ? "" : ` (${detail})`}`);
  if (!ok) failures += 1;
}

async function openPage(context, url) {
  const page = await context.newPage();
  page.errors = [];
  page.on("pageerror", (error) => page.errors.push(`page error: ${error.message}`));
  page.on("console", (message) => {
    if (message.type() === "error") page.errors.push(`console error: ${message.text()}`);
  });
  await page.goto(url, { waitUntil: "load" });
  return page;
}

// The values of one column of the group table, in the order shown.
function column(page, title) {
  return page.evaluate((title) => {
    const headers = Array.from(document.querySelectorAll("#group th")).map((th) => th.textContent);
    const index = headers.indexOf(title);
    return Array.from(document.querySelectorAll("#group tbody tr")).map((row) =>
      row.cells[index].getAttribute("data-value") || row.cells[index].textContent);
  }, title);
}

function ascending(values) {
  const numbers = values.map((v) => (v === "n/a" ? -Infinity : parseFloat(v)));
  return numbers.every((v, i) => i === 0 || numbers[i - 1] <= v);
}

// Counts of the screenshot's pixels by colour, decoded in the page itself.
function countColours(page, png) {
  return page.evaluate(async (base64) => {
    const image = new Image();
    image.src = "data:image/png;base64," + base64;
    await image.decode();
    const canvas = document.createElement("canvas");
    canvas.width = image.width;
    canvas.height = image.height;
    const context = canvas.getContext("2d");
    context.drawImage(image, 0, 0);
    const pixels = context.getImageData(0, 0, image.width, image.height).data;
    const counts = { grey: 0, red: 0, yellow: 0, total: image.width * image.height };
    for (let i = 0; i < pixels.length; i += 4) {
      const [r, g, b] = [pixels[i], pixels[i + 1], pixels[i + 2]];
      if (r > 40 && Math.abs(r - g) < 12 && Math.abs(g - b) < 12) counts.grey += 1;  // the MRI
      if (r > g + 50 && r > b + 50 && g < 200) counts.red += 1;                         // the labelmap at 40 %
      if (r > 150 && g > 110 && b < 0.5 * g && r - g < 90) counts.yellow += 1;          // the surface, shaded
    }
    return counts;
  }, png.toString("base64"));
}

async function cohort(context, pagePath, screenshot) {
  const url = "file://" + pagePath;
  let page = await openPage(context, url);
  const rows = await page.locator("#group tbody tr").count();
  check("cohort: 7 rows (a structure each)", rows === 7, rows);

  await page.click("#group th:text-is('Dice')");
  const dice = await column(page, "Dice");
  check("cohort: Dice sorts ascending on a click", ascending(dice), dice.join(" "));

  const selects = page.locator("#group tbody tr td.rating select");
  await selects.nth(0).selectOption("fail");
  await selects.nth(4).selectOption("pass");
  const rated = await page.evaluate(() => Array.from(document.querySelectorAll("#group tbody tr")).map((r) =>
    [r.dataset.participant, r.dataset.session, r.dataset.structure].join(" ")));
  await page.close();
  page = await openPage(context, url);  // ratings are kept by the browser across visits
  const kept = await page.evaluate(() => {
    const out = {};
    document.querySelectorAll("#group tbody tr").forEach((r) => {
      out[[r.dataset.participant, r.dataset.session, r.dataset.structure].join(" ")] =
        r.querySelector("td.rating select").value;
    });
    return out;
  });
  check("cohort: ratings kept across a reload", kept[rated[0]] === "fail" && kept[rated[4]] === "pass" &&
        Object.values(kept).filter((v) => v === "").length === 5, JSON.stringify(kept));

  const [download] = await Promise.all([page.waitForEvent("download"), page.click("#export")]);
  const tsv = fs.readFileSync(await download.path(), "utf8").trimEnd().split("\n").map((l) => l.split("\t"));
  check("cohort: export is named qc_ratings.tsv", download.suggestedFilename() === "qc_ratings.tsv",
        download.suggestedFilename());
  check("cohort: export has the header and a row per structure",
        tsv[0].join(",") === "participant_id,session_id,structure,rating,flags,t1w" && tsv.length === 8 &&
          tsv.slice(1).every((r) => r[5].endsWith("_T1w.nii.gz")), tsv.length);
  const exported = Object.fromEntries(tsv.slice(1).map((r) => [r.slice(0, 3).join(" "), r[3]]));
  check("cohort: exported ratings are the ones given, the rest n/a", exported[rated[0]] === "fail" &&
        exported[rated[4]] === "pass" && Object.values(exported).filter((v) => v === "n/a").length === 5,
        JSON.stringify(exported));
  const failed = tsv.slice(1).find((r) => r[0] === "sub-04");
  check("cohort: export carries the flags", failed !== undefined && failed[4] === "failed", JSON.stringify(failed));

  const views = await page.locator("button.view").count();
  check("cohort: an interactive view per complete job", views === 3, views);
  await page.locator("button.view").first().click();
  let drawn = true;
  try {
    await page.waitForSelector("#live[data-drawn]", { timeout: 60000 });
    await page.waitForTimeout(1000);  // NiiVue draws on the next animation frames
  } catch (error) {
    drawn = false;
  }
  const status = await page.locator("#live p.status").textContent();
  check("cohort: the interactive view opens", drawn, status);
  if (drawn) {
    const png = await page.locator("#live div.canvas canvas").screenshot({ path: screenshot });
    const counts = await countColours(page, png);
    console.log(`cohort: the view's pixels: ${JSON.stringify(counts)}`);
    // Measured on the 1 mm caudate's view (1261 x 751): 36 % grey, 2.6 % red,
    // 0.40 % yellow. The bars are a quarter of that or less; a blank or
    // half-drawn canvas has none of any, and the crosshair is blue so that red
    // is the labelmap alone.
    check("cohort: the view draws the MRI", counts.grey > 0.10 * counts.total, JSON.stringify(counts));
    check("cohort: the view draws the labelmap overlay", counts.red > 0.005 * counts.total, JSON.stringify(counts));
    check("cohort: the view draws the surface", counts.yellow > 0.001 * counts.total, JSON.stringify(counts));
    await page.click("#live button.close");
    check("cohort: the view closes", !(await page.locator("#live").evaluate((d) => d.open)));
  }
  check("cohort: no script error", page.errors.length === 0, page.errors.join("; "));
}

async function scale(context, pagePath, expected) {
  const start = Date.now();
  const page = await openPage(context, "file://" + pagePath);
  const loaded = Date.now() - start;
  const rows = await page.locator("#group tbody tr").count();
  check(`scale: ${expected} rows`, rows === expected, rows);
  const sortStart = Date.now();
  await page.click("#group th:text-is('volume (mm³)')");
  const volumes = await column(page, "volume (mm³)");
  const sorted = Date.now() - sortStart;
  check("scale: volume sorts ascending on a click", ascending(volumes));
  check("scale: no script error", page.errors.length === 0, page.errors.join("; "));
  console.log(`scale: ${expected} rows loaded in ${loaded} ms, sorted in ${sorted} ms (Chromium already started)`);
}

(async () => {
  const [mode, pagePath, extra] = process.argv.slice(2);
  // SwiftShader is Chromium's software WebGL, all there is without a GPU.
  const browser = await chromium.launch({ executablePath: CHROMIUM,
                                          args: ["--no-sandbox", "--enable-unsafe-swiftshader"] });
  try {
    // One context: its pages share the browser's storage, as a user's tabs do.
    const context = await browser.newContext({ viewport: { width: 1400, height: 1000 }, acceptDownloads: true });
    if (mode === "cohort") await cohort(context, pagePath, extra);
    else if (mode === "scale") await scale(context, pagePath, parseInt(extra, 10));
    else throw new Error(`unknown mode ${mode}`);
  } finally {
    await browser.close();
  }
  process.exit(failures > 0 ? 1 : 0);
})().catch((error) => {
  console.log(`FAILED: ${error.message}`);
  process.exit(1);
});
