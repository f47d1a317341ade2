"""A headless Chromium driven over the DevTools protocol (tests and benchmarks of the page).

Debian's ``chromium`` (``/usr/bin/chromium``) with software GL (SwiftShader through ANGLE) for
WebGL and software compositing, as Chrome runs on a machine without a usable GPU (compositing
the page's layers through SwiftShader too costs the browser about a third more CPU a frame,
docs/benchmarks.md); no sandbox (containers), no network but loopback (a proxy that does not
exist for everything else), a profile of its own in a temporary directory. The protocol is spoken
with ``websockets`` (pinned in requirements.txt): no Playwright and no browser download.
"""

import atexit
import base64
import io
import json
import os
import shutil
import subprocess
import tempfile
import time
import urllib.request

import numpy as np

CHROMIUM = os.environ.get('TWODISK_CHROMIUM', '/usr/bin/chromium')
FLAGS = ('--headless=new', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
         '--no-sandbox', '--no-first-run', '--no-default-browser-check',
         '--disable-background-networking', '--disable-component-update', '--disable-sync',
         '--proxy-server=http://127.0.0.1:9',
         '--remote-debugging-port=0', '--remote-allow-origins=*',
         # a headless page counts as hidden: without these its frames are throttled
         '--disable-background-timer-throttling', '--disable-backgrounding-occluded-windows',
         '--disable-renderer-backgrounding',
         # Chrome's own mode without a GPU: layers composited in software, WebGL in SwiftShader
         '--disable-gpu-compositing')


def missing():
    """None if Chromium can run here, else one line saying what is missing and how to install."""
    if shutil.which(CHROMIUM) is None and not os.access(CHROMIUM, os.X_OK):
        return (f'no Chromium at {CHROMIUM}: install Debian\'s chromium (sudo apt-get install '
                'chromium) or set TWODISK_CHROMIUM')
    return None


class Chromium:
    """One browser with one page of ``width`` × ``height`` CSS pixels (device scale 1)."""

    def __init__(self, width=1280, height=800, timeout=30.0):
        from websockets.sync.client import connect
        self.profile = tempfile.mkdtemp(prefix='twodisk-chromium-')
        self.process = subprocess.Popen(
            [CHROMIUM, *FLAGS, f'--user-data-dir={self.profile}',
             f'--window-size={width},{height}', 'about:blank'],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        atexit.register(self.close)
        try:
            port = self._port(timeout)
            deadline = time.monotonic() + timeout
            while True:
                with urllib.request.urlopen(f'http://127.0.0.1:{port}/json/list',
                                            timeout=5) as answer:
                    pages = [t for t in json.load(answer) if t['type'] == 'page']
                if pages or time.monotonic() > deadline:
                    break
                time.sleep(0.05)
            self._connection = connect(pages[0]['webSocketDebuggerUrl'], max_size=None,
                                       open_timeout=timeout, proxy=None)
            self.socket = self._connection.__enter__()
            self.next_id = 0
            self.width, self.height = width, height
            self.call('Emulation.setDeviceMetricsOverride', width=width, height=height,
                      deviceScaleFactor=1, mobile=False)
            self.call('Page.enable')
        except BaseException:
            self.close()
            raise

    def _port(self, timeout):
        path = os.path.join(self.profile, 'DevToolsActivePort')
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if os.path.exists(path):
                lines = open(path).read().split()
                if lines:
                    return int(lines[0])
            if self.process.poll() is not None:
                raise RuntimeError(f'{CHROMIUM} exited with {self.process.returncode}')
            time.sleep(0.02)
        raise TimeoutError(f'{CHROMIUM} did not open its DevTools port in {timeout} s')

    def call(self, method, timeout=30.0, **params):
        """Send one command; return its result (events in between are dropped)."""
        self.next_id += 1
        ident = self.next_id
        self.socket.send(json.dumps({'id': ident, 'method': method, 'params': params}))
        deadline = time.monotonic() + timeout
        while True:
            message = json.loads(self.socket.recv(timeout=max(0.01, deadline - time.monotonic())))
            if message.get('id') == ident:
                if 'error' in message:
                    raise RuntimeError(f'{method}: {message["error"]}')
                return message.get('result', {})

    def send(self, method, **params):
        """Send one command without waiting for its answer (read later by :meth:`watch`)."""
        self.next_id += 1
        self.socket.send(json.dumps({'id': self.next_id, 'method': method, 'params': params}))

    def watch(self, predicate, start, timeout=30.0):
        """Frames of the page as the compositor makes them (a screencast), until
        ``predicate(image)`` holds: return the seconds from the wall clock ``start``
        (time.time()) to that frame's own timestamp, or None after ``timeout`` s. Commands sent
        with :meth:`send` before are answered in between (their answers are dropped)."""
        from PIL import Image
        deadline = time.monotonic() + timeout
        self.send('Page.startScreencast', format='png', everyNthFrame=1)
        try:
            while time.monotonic() < deadline:
                try:
                    message = json.loads(self.socket.recv(timeout=max(0.01, deadline
                                                                      - time.monotonic())))
                except TimeoutError:
                    break
                if message.get('method') != 'Page.screencastFrame':
                    continue
                frame = message['params']
                self.send('Page.screencastFrameAck', sessionId=frame['sessionId'])
                image = np.asarray(Image.open(io.BytesIO(base64.b64decode(frame['data'])))
                                   .convert('RGB'))
                if predicate(image):
                    return frame['metadata']['timestamp'] - start
            return None
        finally:
            self.call('Page.stopScreencast')

    def evaluate(self, expression, timeout=30.0):
        """The value of a JavaScript expression (promises awaited)."""
        result = self.call('Runtime.evaluate', timeout=timeout, expression=expression,
                           awaitPromise=True, returnByValue=True)
        if 'exceptionDetails' in result:
            raise RuntimeError(f'{expression[:60]}: {result["exceptionDetails"]}')
        return result['result'].get('value')

    def goto(self, url):
        self.call('Page.navigate', url=url)

    def wait_for(self, expression, timeout=30.0, poll=0.05):
        """Wait until a JavaScript expression is truthy; return its value."""
        deadline = time.monotonic() + timeout
        while True:
            value = self.evaluate(expression)
            if value:
                return value
            if time.monotonic() > deadline:
                raise TimeoutError(f'waited {timeout} s for {expression[:80]}')
            time.sleep(poll)

    def screenshot(self, path=None):
        """The page as an (height, width, 3) uint8 array (and a PNG at ``path``)."""
        from PIL import Image
        data = base64.b64decode(self.call('Page.captureScreenshot', format='png')['data'])
        if path is not None:
            with open(path, 'wb') as out:
                out.write(data)
        return np.asarray(Image.open(io.BytesIO(data)).convert('RGB'))

    def key(self, key, code, key_code):
        """Press and release one key in the focused element."""
        for kind in ('rawKeyDown', 'keyUp'):
            self.call('Input.dispatchKeyEvent', type=kind, key=key, code=code,
                      windowsVirtualKeyCode=key_code, nativeVirtualKeyCode=key_code)

    def fps(self, seconds=2.0):
        """Frames a second the page draws (requestAnimationFrame over ``seconds``)."""
        return self.evaluate(
            '(() => new Promise(done => { let n = 0; const t0 = performance.now();'
            ' function f(t) { n++; if (t - t0 < %d) requestAnimationFrame(f);'
            ' else done(n * 1000 / (t - t0)); } requestAnimationFrame(f); }))()'
            % int(1000 * seconds), timeout=seconds + 30)

    def close(self):
        connection = getattr(self, '_connection', None)
        if connection is not None:
            self._connection = None
            connection.__exit__(None, None, None)
        if self.process.poll() is None:
            os.killpg(self.process.pid, 15)     # its own session: the browser's every process
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(self.process.pid, 9)
                self.process.wait()
        shutil.rmtree(self.profile, ignore_errors=True)
