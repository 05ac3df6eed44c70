"""JavaScript run in a page viewer (runtime/web_viewer_page.h) by the tests: frames drawn at given
cameras through window.rsibrViewer, carried out in the DOM for `chromium --dump-dom`."""
import json


def frames_script(viewer, cameras, out_id):
    """A statement that, run after the viewer drew its first frame, appends <pre id=out_id> holding
    JSON [{shown, cover}] per camera (base64: the canvas as shown, 8-bit RGBA top row first; 1 where
    the drawn radiance covers the pixel), or 'ERROR why'. `viewer`: a JS expression for the page's
    window.rsibrViewer (undefined when absent)."""
    return """
(() => {
  const v = %s, out = document.createElement('pre');
  out.id = %s;
  const b64 = u => { let s = ''; for (let i = 0; i < u.length; ++i) s += String.fromCharCode(u[i]); return btoa(s); };
  if (!v || v.error || !v.ready) { out.textContent = 'ERROR ' + (v ? v.error || 'not drawn' : 'no viewer'); }
  else {
    const res = [];
    for (const c of %s) {
      v.setCamera(c);
      const r = v.radiance(), cover = new Uint8Array(r.length / 4);
      for (let i = 0; i < cover.length; ++i) cover[i] = r[4 * i + 3] > 0 ? 1 : 0;
      res.push({ shown: b64(v.displayed()), cover: b64(cover) });
    }
    out.textContent = JSON.stringify(res);
  }
  document.body.appendChild(out);
})();
""" % (viewer, " + ".join(json.dumps(p) for p in (out_id[:3], out_id[3:])), json.dumps(cameras))
