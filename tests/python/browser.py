"""Drives Debian's Chromium, headless, through its DevTools protocol, for the tests of pages the
toolbox writes (the HTML report). Chromium listens on 127.0.0.1 on a port it chooses
(--remote-debugging-port=0) and writes it to DevToolsActivePort in its profile folder; the
protocol runs over a WebSocket, through Debian's python3-websocket (the module websocket of
websocket-client). Without that module a Browser skips the tests that open one, as they are
skipped without Chromium.
"""
import json
import os
import shutil
import subprocess
import tempfile
import time
import unittest
import urllib.request

try:
    import websocket
except ImportError:
    websocket = None

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


class Browser:
    """A headless Chromium with one page, driven through the DevTools protocol. Collects the
    page's console messages, uncaught exceptions and log entries in `console`."""

    def __init__(self, folder, width=1400, height=1000):
        if websocket is None:
            raise unittest.SkipTest("python3-websocket is not installed (apt-get install "
                                    "python3-websocket): the DevTools protocol runs over a "
                                    "WebSocket")
        self.profile = tempfile.mkdtemp(prefix="chromium_", dir=str(folder))
        self.process = subprocess.Popen(
            [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
             "--no-default-browser-check", "--hide-scrollbars", "--remote-debugging-port=0",
             "--remote-debugging-address=127.0.0.1", "--user-data-dir=" + self.profile,
             "--window-size=%d,%d" % (width, height), "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        self.ws, self.next_id, self.events, self.console = None, 0, [], []
        try:
            port = self._port()
            with urllib.request.urlopen("http://127.0.0.1:%d/json/list" % port, timeout=10) as r:
                targets = json.load(r)
            page = [t for t in targets if t.get("type") == "page"][0]
            # No Origin header: Chromium refuses DevTools connections that name an origin it
            # was not started to allow (--remote-allow-origins).
            self.ws = websocket.create_connection(page["webSocketDebuggerUrl"], timeout=30,
                                                  suppress_origin=True)
            for domain in ("Page", "Runtime", "Log"):
                self.call(domain + ".enable")
        except Exception:
            self.close()
            raise

    def _port(self):
        active = os.path.join(self.profile, "DevToolsActivePort")
        deadline = time.time() + 30
        while time.time() < deadline:
            if os.path.exists(active):
                lines = open(active).read().split("\n")
                if lines[0].strip().isdigit():
                    return int(lines[0])
            if self.process.poll() is not None:
                raise AssertionError("chromium exited with %d: %s" % (
                    self.process.returncode, self.process.stderr.read().decode()[-2000:]))
            time.sleep(0.05)
        raise AssertionError("chromium wrote no DevToolsActivePort within 30 s")

    def _record(self, message):
        method = message.get("method", "")
        params = message.get("params", {})
        if method == "Runtime.consoleAPICalled":
            self.console.append("console.%s: %s" % (params["type"], " ".join(
                str(a.get("value", a.get("description", ""))) for a in params.get("args", []))))
        elif method == "Runtime.exceptionThrown":
            details = params["exceptionDetails"]
            self.console.append("exception: %s" % details.get("exception", {}).get(
                "description", details.get("text")))
        elif method == "Log.entryAdded":
            entry = params["entry"]
            self.console.append("log.%s: %s" % (entry["level"], entry["text"]))
        self.events.append(message)

    def _receive(self):
        """The next message of the browser: a command's result or an event."""
        text = self.ws.recv()
        if not text:  # a close frame (recv answers it)
            raise ConnectionError("WebSocket closed by the browser")
        return json.loads(text)

    def call(self, method, **params):
        """Sends one command and returns its result; events that arrive meanwhile are kept."""
        self.next_id += 1
        ident = self.next_id
        self.ws.send(json.dumps({"id": ident, "method": method, "params": params}))
        while True:
            message = self._receive()
            if message.get("id") == ident:
                if "error" in message:
                    raise AssertionError("%s: %s" % (method, message["error"]))
                return message.get("result", {})
            self._record(message)

    def wait_event(self, method, timeout=30):
        deadline = time.time() + timeout
        for message in self.events:
            if message.get("method") == method:
                return message
        while time.time() < deadline:
            message = self._receive()
            self._record(message)
            if message.get("method") == method:
                return message
        raise AssertionError("no %s within %d s" % (method, timeout))

    def evaluate(self, expression):
        """The value of a JavaScript expression in the page (JSON-serialisable values)."""
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True,
                           awaitPromise=True)
        if "exceptionDetails" in result:
            raise AssertionError("%s: %s" % (expression, result["exceptionDetails"]))
        return result["result"].get("value")

    def open(self, path, ready="true", timeout=30):
        """Loads a file and waits until the JavaScript expression `ready` is true."""
        self.events.clear()
        self.call("Page.navigate", url="file://" + os.path.abspath(str(path)))
        self.wait_event("Page.loadEventFired", timeout)
        deadline = time.time() + timeout
        while not self.evaluate("Boolean(%s)" % ready):
            if time.time() > deadline:
                raise AssertionError("the page did not get ready: " + ready)
            time.sleep(0.05)

    def click(self, x, y):
        """A left click at (x, y), CSS pixels of the viewport: moved, pressed, released."""
        self.call("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y)
        for kind in ("mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left",
                      clickCount=1)

    def close(self):
        if self.ws:
            try:
                self.ws.close()
            except (OSError, websocket.WebSocketException):
                pass
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        if self.process.stderr:
            self.process.stderr.close()
        shutil.rmtree(self.profile, ignore_errors=True)
