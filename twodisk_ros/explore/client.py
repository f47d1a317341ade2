"""The page's client: viser's three.js client with one setting of its own for software GL.

viser (1.1.1) creates its WebGL context with multisampling (the three.js renderer's
``antialias: true``) and offers no way to turn it off. A browser with no usable GPU draws
WebGL in software (SwiftShader, llvmpipe), where multisampling doubles the cost of each frame
of the page (docs/benchmarks.md "The page in a browser"). :data:`SCRIPT`, run before the
client, asks the browser which renderer it has and, in software only, creates the WebGL
contexts without multisampling (edges then step by a pixel); a browser with a GPU keeps
viser's settings. :func:`with_settings` puts it in an HTML page; :func:`viser_server` serves
viser's client with it; the exported lesson (cli.export) carries it too.
"""

import atexit
import os
import shutil
import tempfile
import threading

__all__ = ['SCRIPT', 'SOFTWARE_GL', 'viser_server', 'with_settings']

#: Renderer names of software GL (the WebGL renderer string as the browser reports it).
SOFTWARE_GL = ('SwiftShader', 'llvmpipe', 'softpipe', 'Software Rasterizer')

#: Run first in the page: in software GL, WebGL contexts without multisampling.
SCRIPT = """<script>(() => {
  // twodisk-explore (explore/client.py): software GL pays twice for multisampling
  const probe = document.createElement('canvas');
  const gl = probe.getContext('webgl2') || probe.getContext('webgl');
  if (!gl) return;
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  const lose = gl.getExtension('WEBGL_lose_context');
  if (lose) lose.loseContext();
  window.twodiskSoftwareGL = %s.some(word => name.includes(word));
  if (!window.twodiskSoftwareGL) return;
  const getContext = HTMLCanvasElement.prototype.getContext;
  HTMLCanvasElement.prototype.getContext = function (kind, attributes) {
    if (kind === 'webgl2' || kind === 'webgl')
      attributes = Object.assign({}, attributes, {antialias: false});
    return getContext.call(this, kind, attributes);
  };
})();</script>""" % ('[' + ', '.join(f"'{word}'" for word in SOFTWARE_GL) + ']')


def with_settings(html):
    """``html`` (a page of viser's client) with :data:`SCRIPT` first in its head."""
    at = html.find('<head>')
    at = 0 if at < 0 else at + len('<head>')
    return html[:at] + SCRIPT + html[at:]


_root = None
_lock = threading.Lock()


def _client_root():
    """A directory (removed at exit) holding viser's built client, its index.html with
    :data:`SCRIPT` (the other files linked); made once per process."""
    global _root
    import viser
    with _lock:
        if _root is None:
            build = os.path.join(os.path.dirname(viser.__file__), 'client', 'build')
            root = tempfile.mkdtemp(prefix='twodisk-explore-client-')
            atexit.register(shutil.rmtree, root, True)
            for name in os.listdir(build):
                if name != 'index.html':
                    os.symlink(os.path.join(build, name), os.path.join(root, name))
            with open(os.path.join(build, 'index.html'), encoding='utf-8') as page:
                html = with_settings(page.read())
            with open(os.path.join(root, 'index.html'), 'w', encoding='utf-8') as page:
                page.write(html)
            _root = root
        return _root


def viser_server(host, port):
    """A ``viser.ViserServer(host, port, verbose=False)`` whose page is viser's client with
    :data:`SCRIPT` (viser's HTTP root is chosen in its constructor only: its websocket
    server class is swapped for the call, under a lock)."""
    import pathlib
    import viser
    from viser import infra
    root = pathlib.Path(_client_root())

    class _Server(infra.WebsockServer):
        def __init__(self, *args, **kwargs):
            kwargs['http_server_root'] = root
            super().__init__(*args, **kwargs)

    with _lock:
        original = infra.WebsockServer
        infra.WebsockServer = _Server
        try:
            return viser.ViserServer(host=host, port=port, verbose=False)
        finally:
            infra.WebsockServer = original
