"""GL layer: headless EGL context, offscreen framebuffers, queries, cameras and shader loading."""

from .camera import Camera
from .context import GLUnavailable, create_context, renderer
from .framebuffer import Framebuffer, write_masks
from .queries import GpuTimer, PrimitivesGenerated, SamplesPassed, VertexShaderInvocations
from .shaders import load_program

__all__ = ["Camera", "Framebuffer", "GLUnavailable", "GpuTimer", "PrimitivesGenerated",
           "SamplesPassed", "VertexShaderInvocations", "create_context", "load_program",
           "renderer", "write_masks"]
