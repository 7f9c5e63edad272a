"""The EGL devices of this machine and the choice of one: ``--device N``, else
``WORKBENCH_EGL_DEVICE``, else device 0.

EGL lists devices in its own order (EGL_EXT_device_enumeration), which is not CUDA's order, and
``CUDA_VISIBLE_DEVICES`` does not change it. A device is identified in results by its UUID
(EGL_EXT_device_persistent_id) where the driver gives one, else by its DRM render node or
device file, else as Mesa's software device; :attr:`EGLDevice.identity` is that name, prefixed
by its index.

PyOpenGL does not bind the device entry points, so they are fetched with eglGetProcAddress.
"""

from __future__ import annotations

import ctypes
import os
from dataclasses import dataclass
from functools import cache

DEVICE_ENV = "WORKBENCH_EGL_DEVICE"
EGL_EXTENSIONS = 0x3055
EGL_DRM_DEVICE_FILE_EXT = 0x3233
EGL_CUDA_DEVICE_NV = 0x323A
EGL_DEVICE_UUID_EXT = 0x335C
EGL_DRIVER_NAME_EXT = 0x335E
EGL_DRM_RENDER_NODE_FILE_EXT = 0x3377
EGL_DEVICE_EXT = 0x322C


@dataclass(frozen=True)
class EGLDevice:
    """One EGL device: its ``index`` in EGL's order and what the driver says of it (None where
    it does not say): device ``extensions``, ``drm_file`` and ``render_node`` (DRM device
    files), ``cuda_device`` (CUDA's ordinal, EGL_NV_device_cuda), ``uuid`` (hex) and
    ``driver``. ``renderer`` and ``vendor`` are GL's strings, filled by
    :func:`~workbench.gl.context.probed_devices` (a context made on the device and
    released)."""

    index: int
    extensions: tuple[str, ...] = ()
    drm_file: str | None = None
    render_node: str | None = None
    cuda_device: int | None = None
    uuid: str | None = None
    driver: str | None = None
    renderer: str | None = None
    vendor: str | None = None

    @property
    def software(self) -> bool:
        """Whether this is Mesa's software device (llvmpipe)."""
        return "EGL_MESA_device_software" in self.extensions

    @property
    def identity(self) -> str:
        """What tells this device from any other in results: ``egl<index>:`` and its UUID,
        else its render node or DRM file, else ``software`` (Mesa's device) or ``unknown``."""
        name = self.uuid or self.render_node or self.drm_file or (
            "software" if self.software else "unknown")
        return f"egl{self.index}:{name}"


class _EGL:
    """The EGL device entry points (None where libEGL or the extension is missing)."""

    def __init__(self) -> None:
        lib = ctypes.CDLL("libEGL.so.1")
        lib.eglGetProcAddress.restype = ctypes.c_void_p
        lib.eglGetProcAddress.argtypes = [ctypes.c_char_p]
        lib.eglGetCurrentDisplay.restype = ctypes.c_void_p

        def entry(name: bytes, restype, *argtypes):
            address = lib.eglGetProcAddress(name)
            return ctypes.CFUNCTYPE(restype, *argtypes)(address) if address else None

        void_p, int_, uint = ctypes.c_void_p, ctypes.c_int, ctypes.c_uint
        self.current_display = lib.eglGetCurrentDisplay
        self.query_devices = entry(b"eglQueryDevicesEXT", uint, int_,
                                   ctypes.POINTER(void_p), ctypes.POINTER(int_))
        self.device_string = entry(b"eglQueryDeviceStringEXT", ctypes.c_char_p, void_p, int_)
        self.device_attrib = entry(b"eglQueryDeviceAttribEXT", uint, void_p, int_,
                                   ctypes.POINTER(ctypes.c_ssize_t))
        self.device_binary = entry(b"eglQueryDeviceBinaryEXT", uint, void_p, int_, int_,
                                   void_p, ctypes.POINTER(int_))
        self.display_attrib = entry(b"eglQueryDisplayAttribEXT", uint, void_p, int_,
                                    ctypes.POINTER(void_p))

    def handles(self) -> list[int]:
        """The EGL device handles in EGL's order ([] where enumeration is not available)."""
        if self.query_devices is None:
            return []
        count = ctypes.c_int()
        if not self.query_devices(0, None, ctypes.byref(count)) or count.value <= 0:
            return []
        array = (ctypes.c_void_p * count.value)()
        if not self.query_devices(count.value, array, ctypes.byref(count)):
            return []
        return [array[i] for i in range(count.value)]

    def string(self, handle: int, name: int) -> str | None:
        if self.device_string is None:
            return None
        found = self.device_string(handle, name)
        return found.decode(errors="replace") if found else None

    def device(self, index: int, handle: int) -> EGLDevice:
        extensions = tuple((self.string(handle, EGL_EXTENSIONS) or "").split())
        cuda = uuid = None
        if "EGL_NV_device_cuda" in extensions and self.device_attrib is not None:
            value = ctypes.c_ssize_t()
            if self.device_attrib(handle, EGL_CUDA_DEVICE_NV, ctypes.byref(value)):
                cuda = int(value.value)
        if "EGL_EXT_device_persistent_id" in extensions and self.device_binary is not None:
            buffer, size = (ctypes.c_ubyte * 16)(), ctypes.c_int()
            if self.device_binary(handle, EGL_DEVICE_UUID_EXT, 16, buffer, ctypes.byref(size)):
                uuid = bytes(buffer[:size.value]).hex()
        return EGLDevice(
            index=index, extensions=extensions,
            drm_file=self.string(handle, EGL_DRM_DEVICE_FILE_EXT),
            render_node=(self.string(handle, EGL_DRM_RENDER_NODE_FILE_EXT)
                         if "EGL_EXT_device_drm_render_node" in extensions else None),
            cuda_device=cuda, uuid=uuid,
            driver=(self.string(handle, EGL_DRIVER_NAME_EXT)
                    if "EGL_EXT_device_persistent_id" in extensions else None))

    def current_index(self) -> int | None:
        """The index of the device of the current EGL display, None where EGL cannot say."""
        display = self.current_display()
        if not display or self.display_attrib is None:
            return None
        handle = ctypes.c_void_p()
        if not self.display_attrib(display, EGL_DEVICE_EXT, ctypes.byref(handle)):
            return None
        handles = self.handles()
        return handles.index(handle.value) if handle.value in handles else None


@cache
def _egl() -> _EGL | None:
    try:
        return _EGL()
    except (OSError, AttributeError):  # no libEGL.so.1
        return None


def egl_devices() -> list[EGLDevice]:
    """Every EGL device in EGL's order ([] where libEGL or device enumeration is missing);
    :func:`~workbench.gl.context.probed_devices` adds each one's GL renderer and vendor."""
    egl = _egl()
    if egl is None:
        return []
    return [egl.device(i, handle) for i, handle in enumerate(egl.handles())]


def device_handle(index: int) -> int:
    """The EGLDeviceEXT handle of device ``index`` (for eglGetPlatformDisplayEXT); ValueError
    where EGL lists no such device."""
    egl = _egl()
    handles = egl.handles() if egl is not None else []
    if not 0 <= index < len(handles):
        raise ValueError(f"EGL lists no device {index} ({len(handles)} devices)")
    return handles[index]


def current_device() -> EGLDevice | None:
    """The EGL device of the current context, None where EGL cannot say."""
    egl = _egl()
    index = egl.current_index() if egl is not None else None
    if index is None:
        return None
    return egl.device(index, egl.handles()[index])


def device_index(device: int | str | None = None) -> int:
    """The EGL device to draw on: ``device`` if given, else ``WORKBENCH_EGL_DEVICE``, else 0.

    Refused (ValueError, one line): a value that is not a whole number, or an index outside
    the devices EGL lists (naming how many there are)."""
    source = "--device"
    if device is None:
        device, source = os.environ.get(DEVICE_ENV), DEVICE_ENV
        if device is None or device.strip() == "":
            return 0
    try:
        index = int(device)
    except (TypeError, ValueError):
        raise ValueError(f"{source} {device!r}: expected an EGL device index "
                         f"(workbench info lists them)") from None
    if index < 0:
        raise ValueError(f"{source} {index}: an EGL device index is 0 or more")
    count = len(egl_devices())
    if count and index >= count:
        listed = "device 0" if count == 1 else f"devices 0 to {count - 1}"
        raise ValueError(f"{source} {index}: this machine has {count} EGL "
                         f"device{'s' if count != 1 else ''} ({listed}; workbench info "
                         f"lists them)")
    return index
