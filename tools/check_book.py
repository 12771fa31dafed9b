"""Check the built book as a reader sees it, offline, in headless Chromium.

Usage: python tools/check_book.py [book/_build/html] [--screenshots DIR] [--width PX]
(or `make check-book`). Opens every page of the built book with the network blocked
(host names resolve to nothing, every other connection goes to a proxy that does not exist,
and any http(s) request the page still makes is refused and reported), lets its scripts run,
waits for MathJax to typeset, and fails if a page
- asked for anything from the internet,
- still shows TeX in its rendered text (\\( \\) \\[ \\] $$ outside code) or a math element
  MathJax did not typeset, or a TeX error,
- has an image that did not load (naturalWidth 0),
- has a table, code block, output or equation that is wider than the text column and is
  neither scrolled inside its own box nor wrapped (cut off, or widening the page).
It saves a full-page screenshot of each page under book/_build/screenshots/ (a page taller
than 16000 px in parts: ch05_msk.png, ch05_msk-2.png, ...). Debian's `chromium` is installed
with apt-get when missing.

`remote_references(html_dir)` is the static part (no browser): every <script src>,
<link href> (stylesheets, fonts, preloads, icons), media src and CSS @import/url() of the built
files that points to another host; tests/test_book_offline.py uses it.
"""
import argparse
import base64
import fcntl
import json
import os
import queue
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

ROOT = Path(__file__).resolve().parents[1]
REMOTE = re.compile(r"^\s*(?:[a-z][a-z0-9+.-]*:)?//", re.I)  # http://, https://, //host
CSS_URL = re.compile(r"""(?:@import\s+(?:url\(\s*)?|url\(\s*)(['"]?)([^'")\s]+)\1""", re.I)
# a quoted remote script, stylesheet or font in inline JavaScript (e.g. a loader's URL)
ASSET_IN_JS = re.compile(r"""["'`]((?:https?:)?//[^"'`\s]+\.(?:m?js|css|woff2?|ttf|otf|eot)"""
                         r"""(?:\?[^"'`\s]*)?)["'`]""", re.I)
LINK_ASSET_RELS = {"stylesheet", "preload", "modulepreload", "prefetch", "icon", "shortcut",
                   "apple-touch-icon", "mask-icon", "manifest", "preconnect", "dns-prefetch"}
MEDIA_ATTRS = {"img": ("src", "srcset"), "source": ("src", "srcset"), "iframe": ("src",),
               "embed": ("src",), "object": ("data",), "video": ("src", "poster"),
               "audio": ("src",), "track": ("src",), "image": ("href", "xlink:href"),
               "use": ("href", "xlink:href")}
PAGE_SKIP_DIRS = {"_static", "_sources", "_images", "_downloads"}
MAX_SHOT_HEIGHT = 16000


def is_remote(url: str) -> bool:
    return bool(REMOTE.match(url or ""))


class _AssetParser(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.found, self._in = [], None

    def handle_starttag(self, tag, attrs):
        a = {k: (v or "") for k, v in attrs}
        if tag == "script" and is_remote(a.get("src")):
            self.found.append(f"<script src={a['src']}>")
        elif tag == "link" and is_remote(a.get("href")):
            rels = set(a.get("rel", "").lower().split())
            if rels & LINK_ASSET_RELS or a.get("as"):
                self.found.append(f"<link rel={a.get('rel')} href={a['href']}>")
        for attr in MEDIA_ATTRS.get(tag, ()):
            for url in (u.strip().split(" ")[0] for u in a.get(attr, "").split(",")):
                if is_remote(url):
                    self.found.append(f"<{tag} {attr}={url}>")
        if a.get("style"):
            self.found += [f"style url({u})" for u in css_remote_urls(a["style"])]
        self._in = tag if tag in ("style", "script") else None

    def handle_endtag(self, tag):
        self._in = None

    def handle_data(self, data):
        if self._in == "style":
            self.found += [f"<style> url({u})" for u in css_remote_urls(data)]
        elif self._in == "script":
            self.found += [f"<script> loads {u}" for u in ASSET_IN_JS.findall(data)]


def css_remote_urls(css: str) -> list:
    """Remote targets of @import and url() in a piece of CSS."""
    css = re.sub(r"/\*.*?\*/", "", css, flags=re.S)
    return [u for _, u in CSS_URL.findall(css) if is_remote(u)]


def remote_references(html_dir) -> list:
    """'file: reference' for every remote script, stylesheet, font, preload, media source or
    CSS @import/url() in the built HTML and CSS under html_dir (links in <a href> are fine)."""
    html_dir = Path(html_dir)
    out = []
    for f in sorted(html_dir.rglob("*.html")):
        p = _AssetParser()
        p.feed(f.read_text(encoding="utf-8", errors="replace"))
        out += [f"{f.relative_to(html_dir)}: {x}" for x in p.found]
    for f in sorted(html_dir.rglob("*.css")):
        out += [f"{f.relative_to(html_dir)}: url({u})"
                for u in css_remote_urls(f.read_text(encoding="utf-8", errors="replace"))]
    return out


REDIRECT = re.compile(r"""<meta\s+http-equiv=["']?refresh""", re.I)


def book_pages(html_dir) -> list:
    """Every page of the built book (not the redirect stub index.html, nor theme templates)."""
    html_dir = Path(html_dir)
    return sorted(p for p in html_dir.rglob("*.html")
                  if not PAGE_SKIP_DIRS & set(p.relative_to(html_dir).parts[:-1])
                  and not REDIRECT.search(p.read_text(encoding="utf-8", errors="replace")[:2000]))


# --- the browser ---------------------------------------------------------------------------

def ensure_chromium() -> str:
    exe = shutil.which("chromium")
    if exe:
        return exe
    if os.geteuid() != 0:
        sys.exit("check_book: Debian's chromium is not installed; run `sudo apt-get install -y chromium`")
    print("check_book: installing Debian's chromium (apt-get) ...", flush=True)
    subprocess.run(["apt-get", "update", "-q"], check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["apt-get", "install", "-y", "-q", "chromium"], check=True,
                   stdout=subprocess.DEVNULL, env={**os.environ, "DEBIAN_FRONTEND": "noninteractive"})
    exe = shutil.which("chromium")
    if not exe:
        sys.exit("check_book: apt-get installed chromium but /usr/bin/chromium is missing")
    return exe


class Browser:
    """Headless Chromium driven over the DevTools protocol on a pipe (fds 3 and 4)."""

    def __init__(self, exe, width, height, log_path):
        to_chrome_r, self._w = os.pipe()
        self._r, from_chrome_w = os.pipe()
        # keep the child's ends above fd 4 so that dup2 onto 3 and 4 cannot clobber them
        hi_r = fcntl.fcntl(to_chrome_r, fcntl.F_DUPFD_CLOEXEC, 10)
        hi_w = fcntl.fcntl(from_chrome_w, fcntl.F_DUPFD_CLOEXEC, 10)
        os.close(to_chrome_r)
        os.close(from_chrome_w)

        def child_fds():
            os.dup2(hi_r, 3)
            os.dup2(hi_w, 4)

        self._profile = tempfile.mkdtemp(prefix="check_book_profile_")
        args = [exe, "--headless", "--remote-debugging-pipe", "--no-sandbox", "--disable-gpu",
                "--disable-dev-shm-usage", "--no-first-run", "--no-default-browser-check",
                "--disable-background-networking", "--disable-component-update",
                "--disable-sync", "--disable-extensions", "--mute-audio",
                "--allow-file-access-from-files",
                # offline: no name resolves, and any direct connection goes to a closed port
                "--host-resolver-rules=MAP * ~NOTFOUND", "--proxy-server=127.0.0.1:9",
                f"--window-size={width},{height}", f"--user-data-dir={self._profile}",
                "about:blank"]
        self._log = open(log_path, "w")
        self.proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=self._log,
                                     stderr=self._log, preexec_fn=child_fds, pass_fds=(3, 4))
        os.close(hi_r)
        os.close(hi_w)
        self._id = 0
        self._replies, self.events = {}, queue.Queue()
        self._lock = threading.Condition()
        threading.Thread(target=self._reader, daemon=True).start()
        self.width, self.height = width, height
        self.urls = {}  # requestId -> what was asked for (file name or URL)

    def _reader(self):
        buf = b""
        while True:
            chunk = os.read(self._r, 1 << 20)
            if not chunk:
                with self._lock:
                    self._replies[None] = {"error": {"message": "chromium closed the pipe"}}
                    self._lock.notify_all()
                return
            buf += chunk
            *msgs, buf = buf.split(b"\0")
            for m in msgs:
                msg = json.loads(m)
                if "id" in msg:
                    with self._lock:
                        self._replies[msg["id"]] = msg
                        self._lock.notify_all()
                else:
                    self.events.put(msg)

    def send(self, method, params=None, session=None, timeout=60):
        with self._lock:
            self._id += 1
            i = self._id
        msg = {"id": i, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._w, json.dumps(msg).encode() + b"\0")
        end = time.monotonic() + timeout
        with self._lock:
            while i not in self._replies and None not in self._replies:
                left = end - time.monotonic()
                if left <= 0:
                    raise TimeoutError(f"{method}: no answer from chromium in {timeout} s")
                self._lock.wait(left)
            reply = self._replies.pop(i, None) or self._replies[None]
        if "error" in reply:
            raise RuntimeError(f"{method}: {reply['error'].get('message')}")
        return reply.get("result", {})

    def full_page_pngs(self, session) -> list:
        """Screenshots of the whole page, top to bottom, each at most MAX_SHOT_HEIGHT px tall:
        the window is made as tall as the part for each shot (Chromium's capture beyond the
        viewport lays the page out differently), then set back."""
        metrics = self.send("Page.getLayoutMetrics", session=session)
        total = int(metrics["cssContentSize"]["height"]) + 1
        size = {"width": self.width, "deviceScaleFactor": 1, "mobile": False}
        shots = []
        try:
            for top in range(0, total, MAX_SHOT_HEIGHT):
                height = min(MAX_SHOT_HEIGHT, total - top)
                self.send("Emulation.setDeviceMetricsOverride", {**size, "height": height}, session)
                self.send("Runtime.evaluate", {"expression": f"window.scrollTo(0, {top}); new Promise("
                          "r => requestAnimationFrame(() => requestAnimationFrame(r)))",
                          "awaitPromise": True}, session)
                png = self.send("Page.captureScreenshot", {"format": "png"}, session, timeout=120)
                shots.append(base64.b64decode(png["data"]))
        finally:
            self.send("Emulation.setDeviceMetricsOverride", {**size, "height": self.height}, session)
            self.send("Runtime.evaluate", {"expression": "window.scrollTo(0, 0)"}, session)
        return shots

    def close(self):
        try:
            self.send("Browser.close", timeout=10)
        except Exception:
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        self._log.close()
        shutil.rmtree(self._profile, ignore_errors=True)


# Runs in the page after its load event; resolves to a report (see check_page).
PAGE_JS = r"""
(async () => {
  const sleep = ms => new Promise(r => setTimeout(r, ms));
  let mathjax = null;
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
    await Promise.race([MathJax.startup.promise, sleep(MATHJAX_TIMEOUT_MS)]);
    mathjax = MathJax.version || '?';
  }
  const imgs = [...document.images];
  imgs.forEach(i => { i.loading = 'eager'; });
  await Promise.race([Promise.all(imgs.map(i => i.decode().catch(() => null))), sleep(20000)]);
  const images = imgs.map(i => ({src: i.getAttribute('src'), ok: i.complete && i.naturalWidth > 0}));

  const skip = 'pre, code, script, style, textarea, mjx-container, .highlight';
  const delim = /\\\(|\\\)|\\\[|\\\]|\$\$/;
  const tex = [];
  const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    if (n.parentElement && n.parentElement.closest(skip)) continue;
    const m = n.data.match(delim);
    if (m) tex.push(n.data.slice(Math.max(0, m.index - 40), m.index + 60).replace(/\s+/g, ' '));
  }
  const mathEls = [...document.querySelectorAll('span.math, div.math')];
  const untypeset = mathEls.filter(e => !e.querySelector('mjx-container'))
                           .map(e => e.textContent.slice(0, 80));
  const texErrors = [...document.querySelectorAll('mjx-merror')]
                    .map(e => e.getAttribute('data-mjx-error') || e.textContent);

  // Wide content: its right edge, followed up through its ancestors, must end inside the text
  // column; a box that scrolls (overflow-x auto/scroll) contains it, one that hides it cuts it.
  const article = document.querySelector('article.bd-article, [role="main"]') || document.body;
  const colRight = article.getBoundingClientRect().right + 1;
  const describe = e => e.tagName.toLowerCase() + (e.className && typeof e.className === 'string'
                        ? '.' + e.className.trim().split(/\s+/).join('.') : '');
  const wide = [];
  // MathJax's hidden copy for screen readers (clipped to nothing) would count in scrollWidth
  const hideMml = document.createElement('style');
  hideMml.textContent = 'mjx-assistive-mml { display: none !important; }';
  document.head.appendChild(hideMml);
  const candidates = article.querySelectorAll('table, pre, img, svg, mjx-container, div.output, div.math, span.math');
  for (const el of candidates) {
    const r = el.getBoundingClientRect();
    if (r.width === 0 && r.height === 0) continue;
    let right = r.left + Math.max(el.scrollWidth || 0, r.width);
    let problem = null;
    for (let a = el; a && a !== article.parentElement; a = a.parentElement) {
      const ox = getComputedStyle(a).overflowX;
      const ar = a.getBoundingClientRect();
      if (right <= ar.right + 1) continue;
      if (ox === 'auto' || ox === 'scroll') { right = ar.right; continue; }
      if (ox === 'hidden' || ox === 'clip') { problem = 'cut off by ' + describe(a); break; }
    }
    if (!problem && right > colRight) problem = 'sticks out of the text column';
    if (problem) wide.push(describe(el) + ' (' + Math.round(right - colRight) + ' px): ' + problem);
  }
  const scrolling = [...article.querySelectorAll('*')].filter(e => e.scrollWidth > e.clientWidth + 1
      && ['auto', 'scroll'].includes(getComputedStyle(e).overflowX)).length;
  const pageWidth = document.documentElement.scrollWidth;
  hideMml.remove();
  return {mathjax, nMath: mathEls.length, nTypeset: document.querySelectorAll('mjx-container').length,
          images, tex, untypeset, texErrors, wide: [...new Set(wide)], scrolling, pageWidth,
          viewWidth: document.documentElement.clientWidth};
})()
"""


def check_page(browser, session, path: Path, shot: Path, mathjax_timeout_s=30):
    """Open one page and return (problems, summary)."""
    url = path.resolve().as_uri()
    while not browser.events.empty():
        browser.events.get_nowait()
    browser.send("Page.navigate", {"url": url}, session)
    remote, failed = [], []
    end = time.monotonic() + 60
    loaded = False
    while time.monotonic() < end and not loaded:
        try:
            ev = browser.events.get(timeout=end - time.monotonic())
        except queue.Empty:
            break
        loaded = _handle_event(browser, session, ev, remote, failed) == "load"
    problems = [] if loaded else ["the page did not finish loading in 60 s"]
    js = PAGE_JS.replace("MATHJAX_TIMEOUT_MS", str(int(1000 * mathjax_timeout_s)))
    res = browser.send("Runtime.evaluate", {"expression": js, "awaitPromise": True,
                                            "returnByValue": True}, session, timeout=120)
    if "exceptionDetails" in res:
        raise RuntimeError(f"{path.name}: page check script failed: {res['exceptionDetails']}")
    r = res["result"]["value"]
    while not browser.events.empty():  # requests made while the scripts ran
        _handle_event(browser, session, browser.events.get_nowait(), remote, failed)

    if remote:
        problems.append(f"asked the internet for {len(remote)} resource(s): " + ", ".join(remote[:5]))
    if failed:
        problems.append(f"{len(failed)} local resource(s) failed to load: " + ", ".join(failed[:5]))
    if r["nMath"] and not r["mathjax"]:
        problems.append(f"{r['nMath']} math element(s) but MathJax did not start")
    if r["untypeset"]:
        problems.append(f"{len(r['untypeset'])} math element(s) not typeset, e.g. {r['untypeset'][0]!r}")
    if r["tex"]:
        problems.append(f"TeX delimiters in the rendered text ({len(r['tex'])}), e.g. {r['tex'][0]!r}")
    if r["texErrors"]:
        problems.append(f"TeX errors: {r['texErrors'][:3]}")
    bad = [i["src"] for i in r["images"] if not i["ok"]]
    if bad:
        problems.append(f"{len(bad)} of {len(r['images'])} image(s) did not load: {bad[:5]}")
    if r["wide"]:
        problems.append(f"wide content not scrollable ({len(r['wide'])}): " + "; ".join(r["wide"][:4]))
    if r["pageWidth"] > r["viewWidth"] + 1:
        problems.append(f"the page scrolls sideways ({r['pageWidth']} px > window {r['viewWidth']} px)")

    for k, png in enumerate(browser.full_page_pngs(session)):  # page.png, page-2.png, ...
        (shot if k == 0 else shot.with_name(f"{shot.stem}-{k + 1}.png")).write_bytes(png)
    summary = (f"math {r['nTypeset']}/{r['nMath']}"
               + (f" (MathJax {r['mathjax']})" if r["mathjax"] else "")
               + f", images {len(r['images']) - len(bad)}/{len(r['images'])}"
               + f", {r['scrolling']} box(es) scroll sideways")
    return problems, summary


def _handle_event(browser, session, ev, remote, failed):
    method, p = ev.get("method"), ev.get("params", {})
    if method == "Fetch.requestPaused":  # only http(s) requests are intercepted: refuse them
        remote.append(p["request"]["url"])
        browser.send("Fetch.failRequest", {"requestId": p["requestId"],
                                           "errorReason": "InternetDisconnected"}, session)
    elif method == "Network.loadingFailed" and p.get("errorText") != "net::ERR_INTERNET_DISCONNECTED":
        failed.append(f"{browser.urls.get(p['requestId'], '?')} ({p.get('errorText')})")
    elif method == "Network.requestWillBeSent":
        browser.urls[p["requestId"]] = unquote(urlsplit(p["request"]["url"]).path).rsplit("/", 1)[-1] \
            if p["request"]["url"].startswith("file:") else p["request"]["url"]
    elif method == "Page.loadEventFired":
        return "load"
    return None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("html_dir", nargs="?", default=str(ROOT / "book" / "_build" / "html"))
    ap.add_argument("--screenshots", default=None,
                    help="where to save the PNGs (default: <html_dir>/../screenshots)")
    ap.add_argument("--width", type=int, default=1366, help="window width in CSS px (laptop)")
    ap.add_argument("--height", type=int, default=768)
    args = ap.parse_args(argv)
    html_dir = Path(args.html_dir)
    pages = book_pages(html_dir)
    if not pages:
        sys.exit(f"check_book: no built pages in {html_dir}; build the book first (make book)")
    shots = Path(args.screenshots) if args.screenshots else html_dir.parent / "screenshots"
    shots.mkdir(parents=True, exist_ok=True)

    static = remote_references(html_dir)
    exe = ensure_chromium()
    version = subprocess.run([exe, "--version"], capture_output=True, text=True).stdout.strip()
    print(f"check_book: {len(pages)} pages of {html_dir}, {version}, {args.width} px wide, offline")
    browser = Browser(exe, args.width, args.height, shots / "chromium.log")
    failures = {}
    t0 = time.monotonic()
    try:
        target = browser.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = browser.send("Target.attachToTarget", {"targetId": target,
                                                         "flatten": True})["sessionId"]
        browser.send("Emulation.setDeviceMetricsOverride", {
            "width": args.width, "height": args.height, "deviceScaleFactor": 1,
            "mobile": False}, session)
        for domain in ("Page", "Network", "Runtime"):
            browser.send(f"{domain}.enable", session=session)
        browser.send("Fetch.enable", {"patterns": [{"urlPattern": "http://*"},
                                                   {"urlPattern": "https://*"}]}, session)
        for page in pages:
            rel = page.relative_to(html_dir).as_posix()
            shot = shots / (rel[:-len(".html")].replace("/", "__") + ".png")
            t = time.monotonic()
            problems, summary = check_page(browser, session, page, shot)
            status = "FAIL" if problems else "ok  "
            print(f"{status} {rel:32s} {summary}, {time.monotonic() - t:.1f} s", flush=True)
            for p in problems:
                print(f"       - {p}")
            if problems:
                failures[rel] = problems
    finally:
        browser.close()
    if static:
        print(f"remote references in the built files ({len(static)}):")
        for s in static[:20]:
            print(f"       - {s}")
    print(f"check_book: {len(pages) - len(failures)} of {len(pages)} pages pass; "
          f"screenshots in {shots} ({time.monotonic() - t0:.0f} s)")
    return 1 if failures or static else 0


if __name__ == "__main__":
    sys.exit(main())
