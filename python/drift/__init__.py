"""drift from Python: ctypes over the installed libdrift (include/drift/bind.h), numpy in and out.

    import drift
    with drift.Context(threads=2) as ctx:
        scene = ctx.load_scene("scenes/cornell-box/cornell_box.json")
        frame = scene.render_hybrid(width=64, height=64, shadows="pcss", ism_vpls=64)
        ref = scene.render_reference(width=64, height=64, spp=64)
        print(drift.diff(ref, frame, ctx=ctx))        # mse, rmse, relmse, psnr, ssim, flip
        drift.save_exr(ctx, "frame.exr", frame)

Images are numpy float32 arrays of shape (height, width, 3), linear radiance. The library is
found from DRIFT_LIBRARY, else beside this package in an install (PREFIX/lib), else by the
loader's search path. docs/python.md has a walk-through.
"""

import ctypes
import ctypes.util
import os

import numpy as np

__all__ = ["Context", "Scene", "Error", "diff", "load_image", "save_exr", "knobs",
           "techniques", "version", "library_path"]


class Error(RuntimeError):
    """A drift call failed; the message is drift_result_string's."""


class _Image(ctypes.Structure):
    _fields_ = [("pixels", ctypes.POINTER(ctypes.c_float)), ("width", ctypes.c_int32),
                ("height", ctypes.c_int32), ("channels", ctypes.c_int32),
                ("stride", ctypes.c_ssize_t)]


class _Report(ctypes.Structure):
    _fields_ = [(n, ctypes.c_double) for n in ("mse", "rmse", "relmse", "psnr", "ssim", "flip")]


class _Layer(ctypes.Structure):
    _fields_ = [("name", ctypes.c_char_p), ("image", ctypes.POINTER(_Image))]


def _find_library():
    if os.environ.get("DRIFT_LIBRARY"):
        return os.environ["DRIFT_LIBRARY"]
    here = os.path.dirname(os.path.abspath(__file__))
    # PREFIX/lib/drift/python/drift/__init__.py -> PREFIX/lib/libdrift.so.*
    libdir = os.path.normpath(os.path.join(here, "..", "..", ".."))
    for name in sorted(os.listdir(libdir)) if os.path.isdir(libdir) else []:
        if name.startswith("libdrift.so"):
            return os.path.join(libdir, name)
    found = ctypes.util.find_library("drift")
    if not found:
        raise ImportError("libdrift not found: set DRIFT_LIBRARY to libdrift.so "
                          "(cmake --install puts it in PREFIX/lib)")
    return found


library_path = _find_library()
_lib = ctypes.CDLL(library_path)
_P = ctypes.c_void_p


def _fn(name, restype, *argtypes):
    f = getattr(_lib, name)
    f.restype, f.argtypes = restype, list(argtypes)
    return f


_result_string = _fn("drift_result_string", ctypes.c_char_p, ctypes.c_int)
_version = _fn("drift_version", ctypes.c_char_p)
_context_create = _fn("drift_context_create", ctypes.c_int, _P, ctypes.POINTER(_P))
_context_destroy = _fn("drift_context_destroy", None, _P)
_scene_load = _fn("drift_scene_load", ctypes.c_int, _P, ctypes.c_char_p, ctypes.POINTER(_P))
_scene_destroy = _fn("drift_scene_destroy", None, _P)
_accel_create = _fn("drift_accel_create", ctypes.c_int, _P, _P, _P, ctypes.POINTER(_P))
_accel_destroy = _fn("drift_accel_destroy", None, _P)
_params_new = _fn("drift_bind_params_new", _P)
_params_free = _fn("drift_bind_params_free", None, _P)
_params_set = _fn("drift_bind_params_set", ctypes.c_int, _P, ctypes.c_char_p, ctypes.c_char_p)
_params_get = _fn("drift_bind_params_get", ctypes.c_double, _P, ctypes.c_char_p)
_knob_count = _fn("drift_bind_knob_count", ctypes.c_uint32)
_knob_name = _fn("drift_bind_knob_name", ctypes.c_char_p, ctypes.c_uint32)
_knob_type = _fn("drift_bind_knob_type", ctypes.c_char_p, ctypes.c_uint32)
_scene_camera = _fn("drift_bind_scene_camera", _P, _P)
_reference = _fn("drift_bind_reference", ctypes.c_int, _P, _P, _P, ctypes.c_int32,
                 ctypes.c_int32, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_int32,
                 ctypes.POINTER(_Image))
_hybrid_create = _fn("drift_hybrid_create", ctypes.c_int, _P, _P, _P, _P, ctypes.POINTER(_P))
_hybrid_destroy = _fn("drift_hybrid_destroy", None, _P)
_hybrid_render = _fn("drift_hybrid_render", ctypes.c_int, _P, _P, _P)
_hybrid_image = _fn("drift_hybrid_image", ctypes.POINTER(_Image), _P)
_image_load = _fn("drift_image_load", ctypes.c_int, _P, ctypes.c_char_p, ctypes.POINTER(_Image))
_image_destroy = _fn("drift_image_destroy", None, _P, ctypes.POINTER(_Image))
_save_exr = _fn("drift_image_save_exr", ctypes.c_int, _P, ctypes.c_char_p,
                ctypes.POINTER(_Layer), ctypes.c_uint32)
_metric_compare = _fn("drift_metric_compare", ctypes.c_int, _P, ctypes.POINTER(_Image),
                      ctypes.POINTER(_Image), _P, ctypes.POINTER(_Report), _P)
_effect_name = _fn("drift_effect_name", ctypes.c_char_p, ctypes.c_int)
_technique_count = _fn("drift_technique_count", ctypes.c_int, ctypes.c_int)
_technique_name = _fn("drift_technique_name", ctypes.c_char_p, ctypes.c_int, ctypes.c_int)


def _check(result, what):
    if result != 0:
        raise Error("%s: %s" % (what, _result_string(result).decode()))


def version():
    """The loaded library's DRIFT_VERSION."""
    return _version().decode()


def knobs():
    """{name: type} of the knobs render_hybrid takes (besides effect=technique)."""
    return {_knob_name(i).decode(): _knob_type(i).decode() for i in range(_knob_count())}


def techniques():
    """{effect: [technique names]} from the library's technique table."""
    out, e = {}, 0
    while True:
        name = _effect_name(e)
        count = _technique_count(e)
        if not name or count <= 0:
            return out
        out[name.decode()] = [_technique_name(e, t).decode() for t in range(count)]
        e += 1


def _to_numpy(image):
    """A copy of a drift_image's RGB as a (height, width, 3) float32 array."""
    h, w, c, stride = image.height, image.width, image.channels, image.stride
    flat = np.ctypeslib.as_array(image.pixels, shape=(h * stride,))
    rows = flat.reshape(h, stride)[:, : w * c].reshape(h, w, c)
    return np.array(rows[:, :, :3], dtype=np.float32, copy=True)


def _from_numpy(array):
    """A drift_image view of a (height, width, 3) array (kept alive by the caller)."""
    a = np.ascontiguousarray(array, dtype=np.float32)
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError("an image is a (height, width, 3) array, got %s" % (a.shape,))
    img = _Image(a.ctypes.data_as(ctypes.POINTER(ctypes.c_float)), a.shape[1], a.shape[0], 3,
                 a.shape[1] * 3)
    return a, img


class Context:
    """A drift context: its thread pool and allocator. Close it (or use `with`) when done."""

    def __init__(self, threads=0):
        class _Desc(ctypes.Structure):  # drift_context_desc: thread_count, logger, allocator
            _fields_ = [("thread_count", ctypes.c_int), ("rest", ctypes.c_void_p * 8)]
        self._ptr = _P()
        _check(_context_create(ctypes.byref(_Desc(threads)), ctypes.byref(self._ptr)), "context")
        self._scenes = []

    def load_scene(self, path):
        """A Scene from a drift JSON scene or a mesh file (docs/scene-format.md)."""
        scene = Scene(self, path)
        self._scenes.append(scene)
        return scene

    def close(self):
        for s in self._scenes:
            s.close()
        self._scenes = []
        if self._ptr:
            _context_destroy(self._ptr)
            self._ptr = _P()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()


class Scene:
    """A loaded scene and its ray-tracing acceleration structure."""

    def __init__(self, ctx, path):
        self.ctx = ctx
        self._scene, self._accel = _P(), _P()
        _check(_scene_load(ctx._ptr, os.fsencode(path), ctypes.byref(self._scene)), str(path))
        _check(_accel_create(ctx._ptr, self._scene, None, ctypes.byref(self._accel)), "accel")

    def render_hybrid(self, **settings):
        """The hybrid frame from drift_hybrid_params_recommended() (what `drift render --mode
        hybrid` starts from) with settings: effect=technique (shadows="pcss") and knobs by
        name (width=64, ism_vpls=64); see knobs() and techniques()."""
        params = _params_new()
        frame = _P()
        try:
            for name, value in settings.items():
                text = ("on" if value else "off") if isinstance(value, bool) else str(value)
                _check(_params_set(params, name.encode(), text.encode()),
                       "%s = %r (knobs(), techniques())" % (name, value))
            _check(_hybrid_create(self.ctx._ptr, self._scene, self._accel, params,
                                  ctypes.byref(frame)), "hybrid frame")
            _check(_hybrid_render(frame, _scene_camera(self._scene), None), "hybrid render")
            return _to_numpy(_hybrid_image(frame).contents)
        finally:
            _hybrid_destroy(frame)
            _params_free(params)

    def render_reference(self, width=0, height=0, spp=64, seed=0, max_depth=0):
        """The path tracer's image (0 width/height: the camera's size; max_depth 0: 8)."""
        img = _Image()
        _check(_reference(self.ctx._ptr, self._scene, self._accel, width, height, spp, seed,
                          max_depth, ctypes.byref(img)), "reference render")
        try:
            return _to_numpy(img)
        finally:
            _image_destroy(self.ctx._ptr, ctypes.byref(img))

    def close(self):
        if self._accel:
            _accel_destroy(self._accel)
            self._accel = _P()
        if self._scene:
            _scene_destroy(self._scene)
            self._scene = _P()


def load_image(ctx, path):
    """An EXR, PNG, JPEG or HDR file as a (height, width, 3) float32 array (linear)."""
    img = _Image()
    _check(_image_load(ctx._ptr, os.fsencode(path), ctypes.byref(img)), str(path))
    try:
        return _to_numpy(img)
    finally:
        _image_destroy(ctx._ptr, ctypes.byref(img))


def save_exr(ctx, path, array):
    """Writes a (height, width, 3) array as a float32 OpenEXR file."""
    keep, img = _from_numpy(array)
    layer = _Layer(None, ctypes.pointer(img))
    _check(_save_exr(ctx._ptr, os.fsencode(path), ctypes.byref(layer), 1), str(path))
    del keep


def diff(reference, test, ctx):
    """drift diff's numbers for two (height, width, 3) arrays: a dict of mse, rmse, relmse,
    psnr, ssim and flip (ꟻLIP)."""
    keep_r, ref = _from_numpy(reference)
    keep_t, tst = _from_numpy(test)
    report = _Report()
    _check(_metric_compare(ctx._ptr, ctypes.byref(ref), ctypes.byref(tst), None,
                           ctypes.byref(report), None), "diff")
    del keep_r, keep_t
    return {name: getattr(report, name) for name, _ in _Report._fields_}
