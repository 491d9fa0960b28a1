"""Type stubs of the native module (crates/prism-python/src); the package re-exports these."""

import os
from typing import (
    Any,
    Callable,
    Dict,
    Iterator,
    List,
    Optional,
    Sequence,
    Set,
    Tuple,
    TypedDict,
    Union,
    overload,
)

import numpy as np
import numpy.typing as npt

class PrismError(Exception):
    """An error in a scene, a file it uses or an argument. ``str()`` is the message the
    ``prism`` command prints."""

    file: Optional[str]
    """The file where the problem is; for a dictionary, the entry's key path, such as
    ``scene.sphere.bsdf.reflectance``; None when no input is to blame."""
    line: Optional[int]
    """1-based line in ``file``; None for a dictionary."""
    column: Optional[int]
    """1-based column in ``file``; None for a dictionary."""
    message: str
    """What is wrong."""
    help: Optional[str]
    """What to do about it, with a "did you mean" where a name is misspelled."""
    kind: str
    """``"input"`` (the scene or an argument is invalid) or ``"io"`` (reading or writing
    failed)."""

class Scene:
    """A scene ready to render, from :func:`load_file` or :func:`load_dict`."""

    @property
    def width(self) -> int:
        """The film's width in pixels."""
    @property
    def height(self) -> int:
        """The film's height in pixels."""
    @property
    def spp(self) -> int:
        """The sampler's ``sample_count``."""
    @property
    def seed(self) -> int:
        """The sampler's ``seed``."""
    @property
    def wavelengths(self) -> str:
        """The density the wavelengths are drawn from (the film's ``wavelength_sampling``):
        ``"balanced"``, ``"cie_sum"``, ``"visible"`` or ``"uniform"``. Setting it is
        ``prism render --wavelengths``; an unknown name raises :class:`PrismError`."""
    @wavelengths.setter
    def wavelengths(self, name: str) -> None: ...
    @property
    def reconstruction(self) -> str:
        """How samples become pixel values (the film's ``reconstruction``): ``"filter_mis"``
        or ``"pixel"``. Setting it is ``prism render --reconstruction``; an unknown name raises
        :class:`PrismError`."""
    @reconstruction.setter
    def reconstruction(self, name: str) -> None: ...
    @property
    def sensor(self) -> int:
        """The index of the sensor the scene is seen through: 0 after loading, then the one the
        last :func:`render` used. ``width``, ``height``, ``spp`` and ``seed`` are its."""
    @property
    def bvh_refit(self) -> bool:
        """Whether the bounding volume hierarchy over the shapes was refit to shapes an update
        moved (True) or built for the shapes where they are (False), as
        :meth:`SceneParameters.update` chooses."""
    @property
    def sensor_ids(self) -> List[Optional[str]]:
        """The ``id`` of every ``<sensor>`` (None for one without), in document order."""
    @overload
    def ray_intersect(self, origins: Ray3f) -> SurfaceInteraction:
        """The closest surface the ray meets before its ``maxt``; the interaction's fields
        are those of this one ray."""
    @overload
    def ray_intersect(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        tmax: Union[None, float, npt.ArrayLike] = None,
    ) -> SurfaceInteraction:
        """The closest surface each ray ``origins[i] + t directions[i]``, 0 < t < ``tmax``,
        meets: (N, 3) arrays (any numeric dtype, traced in float32), ``tmax`` None (no bound),
        one number or N. As Mitsuba's ``scene.ray_intersect``; traced by the renderer's own
        hierarchy on all cores without the GIL, each ray's answer the same for any number of
        threads."""
    @overload
    def ray_test(self, origins: Ray3f) -> bool:
        """Whether anything blocks the ray before its ``maxt`` (a shadow ray)."""
    @overload
    def ray_test(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        tmax: Union[None, float, npt.ArrayLike] = None,
    ) -> npt.NDArray[np.bool_]:
        """Whether anything blocks each ray before its ``tmax``, (N,) bool, as Mitsuba's
        ``scene.ray_test``; the rays as for :meth:`ray_intersect`."""
    def shapes(self) -> List[Shape]:
        """The shapes (and ``instance``s of shape groups), in document order; a shape of zero
        area, which is never hit, is left out."""
    def emitters(self) -> List[Emitter]:
        """The lights: those shapes carry, in the shapes' order, then the scene's
        ``<emitter>``s."""
    def sensors(self) -> List[Sensor]:
        """The sensors, in document order."""
    def bbox(self) -> BoundingBox3f:
        """The box around the shapes (an empty scene's is infinite and inverted)."""

class Ray3f:
    """One ray, as Mitsuba's ``mi.Ray3f``: the points ``o + t d`` for 0 < t < ``maxt``, at
    ``time``; ``d`` need not be of unit length (``t`` is in units of its length)."""

    o: List[float]
    d: List[float]
    maxt: float
    time: float
    def __init__(
        self,
        o: Sequence[float],
        d: Sequence[float],
        maxt: float = ...,
        time: float = 0.0,
    ) -> None: ...
    def __call__(self, t: float) -> List[float]:
        """The point ``o + t d``."""

class SurfaceInteraction:
    """What :meth:`Scene.ray_intersect` found, as Mitsuba's ``SurfaceInteraction3f``: arrays
    with one entry (row) per ray, or for one :class:`Ray3f` that entry alone. Where a ray hits
    nothing, ``t`` is infinite, ``shape`` and ``prim_index`` are -1 and the rest 0."""

    @property
    def t(self) -> Any:
        """(N,) float32: the distance along the ray, in units of its direction's length."""
    @property
    def p(self) -> Any:
        """(N, 3) float32: the point hit."""
    @property
    def n(self) -> Any:
        """(N, 3) float32: the unit geometric normal, on the side the shape calls outside."""
    @property
    def sh_n(self) -> Any:
        """(N, 3) float32: the unit shading normal (interpolated on smooth meshes)."""
    @property
    def uv(self) -> Any:
        """(N, 2) float32: the surface's texture coordinates."""
    @property
    def shape(self) -> Any:
        """(N,) int64: the index of the shape hit in :meth:`Scene.shapes` (as the ``aov``
        integrator's ``shape_index``; a shape group's members follow the scene's shapes)."""
    @property
    def prim_index(self) -> Any:
        """(N,) int64: the triangle within a mesh (0 for other shapes)."""
    def is_valid(self) -> Any:
        """(N,) bool: whether each ray hit a surface."""

class BoundingBox3f:
    """An axis-aligned box, as Mitsuba's ``BoundingBox3f``."""

    @property
    def min(self) -> List[float]: ...
    @property
    def max(self) -> List[float]: ...
    def center(self) -> List[float]: ...
    def extents(self) -> List[float]:
        """``max - min``."""

class Shape:
    """One shape of a scene (:meth:`Scene.shapes`); it reads its scene when asked, so it
    follows :meth:`SceneParameters.update`."""

    @property
    def index(self) -> int:
        """Its place in :meth:`Scene.shapes` (and ``SurfaceInteraction.shape``)."""
    def id(self) -> str:
        """Its ``id``, else the name :func:`traverse` gives it (its key in a dictionary,
        or ``shape_0``, ``shape_1``, …), so that ``f"{shape.id()}.to_world"`` is a parameter
        key."""
    def plugin_type(self) -> str:
        """``obj``, ``ply``, ``sphere``, ``rectangle``, ``instance``, …."""
    def bbox(self) -> BoundingBox3f:
        """The box around it in world space (around its motion, for a moving shape)."""
    def surface_area(self) -> float:
        """Its area in world units (0 for curves)."""
    def is_mesh(self) -> bool: ...
    def is_emitter(self) -> bool:
        """Whether an area light lies on it."""
    def vertex_positions(self) -> npt.NDArray[np.float32]:
        """A mesh's vertices in world space, (V, 3); TypeError for other shapes."""
    def faces(self) -> npt.NDArray[np.uint32]:
        """A mesh's triangles as indices of :meth:`vertex_positions`, (F, 3); TypeError for
        other shapes."""
    def vertex_count(self) -> int: ...
    def face_count(self) -> int: ...

class Emitter:
    """One light of a scene (:meth:`Scene.emitters`)."""

    @property
    def index(self) -> int: ...
    def id(self) -> str:
        """Its ``id``, else the name :func:`traverse` gives it (``light.emitter`` for the
        emitter of a shape ``light``), so that ``f"{emitter.id()}.radiance.value"`` is a
        parameter key."""
    def is_environment(self) -> bool:
        """Whether it is at infinity (``constant``, ``envmap``, ``sunsky``)."""
    def shape(self) -> Optional[int]:
        """The index in :meth:`Scene.shapes` of the shape an area light lies on; None for
        other lights."""

class Sensor:
    """One sensor of a scene (:meth:`Scene.sensors`)."""

    @property
    def index(self) -> int: ...
    def id(self) -> Optional[str]: ...
    def film_size(self) -> Tuple[int, int]:
        """The film's (width, height) in pixels, as Mitsuba's ``sensor.film().size()``."""

ParameterValueIn = Union[float, int, bool, npt.ArrayLike, Transform]
"""A value :class:`SceneParameters` takes: a number, a bool, numbers (a list, tuple or numpy
array), a 4 × 4 matrix or a :class:`Transform`."""

class SceneParameters:
    """The parameters of a scene, from :func:`traverse`: a mapping from keys named as Mitsuba
    3's ``mi.traverse`` names them (``red.reflectance.value``, ``sensor.to_world``,
    ``sensor.x_fov``, ``light.emitter.radiance.value``) to their values. ``params[key] =
    value`` records a change (checked against the parameter's type and shape, else
    :class:`PrismError`); :meth:`update` applies the changes. An unknown key raises
    ``KeyError`` naming the closest key."""

    def keys(self) -> List[str]:
        """The keys, in the order of the scene's description."""
    def items(self) -> List[Tuple[str, Any]]:
        """``(key, value)`` for every parameter, in the order of :meth:`keys`."""
    def __len__(self) -> int: ...
    def __contains__(self, key: str) -> bool: ...
    def __iter__(self) -> Iterator[str]: ...
    def __getitem__(self, key: str) -> Any:
        """The value: a float, int or bool; a float64 array for a colour (3), a point or a
        vector (3) or a sampled spectrum's values (one per wavelength); a
        :class:`Transform`. A change recorded and not yet applied is shown."""
    def __setitem__(self, key: str, value: ParameterValueIn) -> None:
        """Records a change; :meth:`update` applies it."""
    def keep(self, patterns: Union[None, str, Sequence[str]]) -> None:
        """Keeps only the parameters whose keys ``patterns`` match: a regular expression or a
        list of them, each matched at the start of a key (``re.match``), as Mitsuba's
        ``keep`` (changes recorded for the other keys are dropped); None keeps them
        all. A pattern that matches no key raises ``KeyError``."""
    def update(
        self, values: Optional[Dict[str, ParameterValueIn]] = None
    ) -> List[Tuple[str, Set[str]]]:
        """Applies the changes recorded (after setting ``values``, if given): the scene is
        built again from its description with the new values, exactly as if that scene were
        loaded from scratch, but reading no file again, and keeping the hierarchy over the
        shapes when no shape's parameter changed. Returns ``(plugin, {keys})`` for each
        plugin changed, as Mitsuba's ``update``. When the scene refuses a value,
        :class:`PrismError` is raised, the scene stays as it was and the changes stay
        recorded."""

def traverse(scene: Scene) -> SceneParameters:
    """The parameters of ``scene``, as Mitsuba's ``mi.traverse``."""

class Transform:
    """A 4 × 4 transform acting on column vectors, composed like Mitsuba's
    ``ScalarTransform4f``: each method multiplies on the right, so
    ``Transform().translate(t).scale(s)`` scales first, then translates. Give it as a
    ``to_world`` value in :func:`load_dict`."""

    def __init__(self, matrix: Optional[npt.ArrayLike] = None) -> None:
        """The identity, or the 4 × 4 ``matrix`` (rows first)."""
    def translate(self, offset: Union[float, Sequence[float]]) -> Transform:
        """This transform times the translation by ``offset`` (three numbers)."""
    def scale(self, factors: Union[float, Sequence[float]]) -> Transform:
        """This transform times the scaling by ``factors`` (one number or three)."""
    def rotate(self, axis: Sequence[float], angle: float) -> Transform:
        """This transform times the right-handed rotation by ``angle`` degrees about
        ``axis``, taken as given as Mitsuba 3 does: an axis not of unit length also stretches
        and shears. Raises ValueError for a zero axis."""
    def look_at(
        self,
        origin: Sequence[float],
        target: Sequence[float],
        up: Optional[Sequence[float]] = None,
    ) -> Transform:
        """This transform times the camera-to-world transform of a camera at ``origin``
        looking at ``target`` with ``up`` (None: any perpendicular direction), as Mitsuba's
        ``look_at``. Raises ValueError when origin and target coincide or up is parallel to
        the view."""
    def inverse(self) -> Transform:
        """The inverse. Raises ValueError if there is none."""
    @property
    def matrix(self) -> npt.NDArray[np.float64]:
        """The 4 × 4 matrix, rows first (a new array)."""
    @overload
    def __matmul__(self, other: Transform) -> Transform:
        """The product: ``(a @ b)`` applies ``b``, then ``a``."""
    @overload
    def __matmul__(self, other: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The point (three numbers) or points (N × 3) transformed, with the division by w,
        as Mitsuba's ``Transform4f @ Point3f``; an array of the same shape."""

class Image:
    """A rendered image. The arrays are the render's own memory (no copy); ``write`` and
    ``_repr_png_`` use their current values. ``numpy.asarray(image)`` is ``rgb``."""

    @property
    def rgb(self) -> npt.NDArray[np.float32]:
        """H × W × 3, linear sRGB (D65 white)."""
    @property
    def xyz(self) -> npt.NDArray[np.float32]:
        """H × W × 3, CIE 1931 XYZ."""
    @property
    def variance(self) -> npt.NDArray[np.float32]:
        """H × W × 3, the estimated variance of each pixel's mean of X, Y and Z."""
    @property
    def relative_error(self) -> npt.NDArray[np.float32]:
        """H × W, each pixel's relative standard error of luminance (Y)."""
    @property
    def aovs(self) -> Dict[str, npt.NDArray[np.float32]]:
        """The integrator's extra channels (``aov``, ``moment``) by their EXR names, each
        H × W; empty for other integrators. :meth:`write` writes them."""
    @property
    def spp(self) -> int:
        """Samples per pixel taken (for an image read from a file, as its header records
        them, else 0)."""
    @property
    def seconds(self) -> float:
        """How long the render took (for an image read from a file, as its header records
        it, else 0)."""
    @property
    def seed(self) -> Optional[int]:
        """The seed of the render's random numbers (None for a file that does not record
        it)."""
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @staticmethod
    def read(path: Union[str, os.PathLike]) -> Image:
        """Reads an OpenEXR file that Prism wrote (``prism render`` or :meth:`write`) with
        the film's default ``pixel_format`` ``rgb``, 32-bit or half; its channels other than
        the image's are the ``aovs``. :func:`read_image` reads any image file."""
    def __array__(
        self, dtype: Optional[npt.DTypeLike] = None, copy: Optional[bool] = None
    ) -> npt.NDArray[np.float32]:
        """``rgb``, converted to ``dtype`` or copied where asked."""
    def write(self, path: Union[str, os.PathLike]) -> None:
        """Writes ``.exr`` (every array and the ``aovs``, the channels ``prism render``
        writes) or ``.png``
        (the RGB image, 8-bit sRGB)."""
    def _repr_png_(self) -> bytes:
        """The PNG that :meth:`write` writes, for Jupyter."""

class RenderState:
    """The exact pixel sums of a render over some sample ranges, from
    ``render(..., sample_range=(start, end))``, :func:`merge` or a state file; what they belong
    to (the scene, seed, sampler, samples per pixel, film and crop) travels with them. It
    pickles as the bytes of its file, so task engines (dask, Ray, multiprocessing) carry it."""

    @staticmethod
    def read(path: Union[str, os.PathLike]) -> RenderState:
        """Reads a state file (``prism render --checkpoint``'s or :meth:`write`'s)."""
    @staticmethod
    def from_bytes(data: bytes) -> RenderState:
        """The state whose file holds ``data``; :class:`PrismError` when it is damaged."""
    def to_bytes(self) -> bytes:
        """The bytes of the state's file."""
    def write(self, path: Union[str, os.PathLike]) -> None:
        """Writes the state's file atomically, for ``prism merge`` or ``--resume``."""
    @property
    def ranges(self) -> List[Tuple[int, int]]:
        """The sample index ranges ``(start, end)`` every pixel holds, sorted."""
    @property
    def spp(self) -> int:
        """Samples per pixel the state holds."""
    @property
    def seed(self) -> int:
        """The seed of the render's random numbers."""
    def image(self) -> Image:
        """The image of the sums, as ``prism merge`` writes it (``seconds`` is 0)."""

def merge(states: Sequence[Union[RenderState, str, os.PathLike]]) -> RenderState:
    """The state of one render of all the samples of ``states`` (each a :class:`RenderState`
    or a state file's path), as ``prism merge``: their ranges must be disjoint and their renders
    the same (scene, ``spp``, ``seed``, ``crop``), else :class:`PrismError`. The sums are exact,
    so the merged image is the single render's bit for bit, in any order of merging."""

class ChannelDifference:
    """How one channel of two images differs."""

    @property
    def name(self) -> str: ...
    @property
    def mean_test(self) -> float: ...
    @property
    def mean_reference(self) -> float: ...
    @property
    def mse(self) -> float: ...
    @property
    def rel_mse(self) -> float:
        """Mean of (a − b)² / (b² + 0.01)."""
    @property
    def max_abs(self) -> float:
        """The largest |a − b|."""

class ZTest:
    """The per-pixel z-test zᵢ = (aᵢ − bᵢ)/√(σ²_a + σ²_b) of luminance."""

    @property
    def pixels(self) -> int: ...
    @property
    def chi2(self) -> float:
        """Σ zᵢ²."""
    @property
    def p_value(self) -> float:
        """The χ² p-value of ``chi2`` with ``pixels`` degrees of freedom."""
    @property
    def max_z(self) -> float: ...
    @property
    def max_z_p_value(self) -> float:
        """The two-sided p-value of ``max_z`` times ``pixels`` (Bonferroni)."""
    @property
    def beyond_three(self) -> float:
        """The fraction of pixels with |z| > 3 (0.27 % expected from noise)."""
    @property
    def consistent_with_noise(self) -> bool:
        """Whether both p-values exceed 0.01."""

class Comparison:
    """The outcome of :func:`compare`; ``str()`` is ``prism compare``'s table."""

    @property
    def channels(self) -> List[ChannelDifference]: ...
    @property
    def mse(self) -> float:
        """The MSE averaged over the channels."""
    @property
    def rel_mse(self) -> float:
        """The relative MSE averaged over the channels."""
    @property
    def z_test(self) -> Optional[ZTest]:
        """None when the test image has no variances."""

def load_file(path: Union[str, os.PathLike], defines: List[Tuple[str, str]] = ...) -> Scene:
    """Loads a Mitsuba XML scene with ``(name, value)`` defines, or a pbrt-v4 scene (``.pbrt``)."""

def load_dict(scene: dict) -> Scene:
    """Loads a scene in Mitsuba's dictionary form: ``{"type": "scene", "ball": {"type":
    "sphere", ...}}``. Values: bool, int, float, str, path-like, three numbers (a point or
    vector), a 4 × 4 matrix (nested lists, numpy array or :class:`Transform`),
    ``{"type": "rgb", "value": ...}``, ``{"type": "spectrum", "value": ...}`` (one number or
    (wavelength, value) pairs) or ``{"type": "spectrum", "filename": ...}``,
    ``{"type": "ref", "id": ...}``, and nested plugins. Plugins directly in the scene can be
    referred to by their key. Raises :class:`PrismError` with ``file`` the key path."""

def load_string(text: str, defines: List[Tuple[str, str]] = ...) -> Scene:
    """Loads a Mitsuba XML scene given as text with ``(name, value)`` defines; messages name
    it ``<string>``."""

class _RenderSettings(TypedDict):
    spp: Optional[int]
    seed: Optional[int]
    threads: Optional[int]
    time_limit: Optional[float]
    target_error: Optional[float]
    sensor: Union[int, str]
    crop: Optional[Tuple[int, int, int, int]]
    checkpoint: Optional[str]
    checkpoint_every: float
    resume: Optional[str]
    sample_range: Optional[Tuple[int, int]]

def render(
    scene: Scene,
    settings: _RenderSettings,
    progress: Optional[Callable[[int, Optional[int], float], object]] = None,
    preview: Optional[Callable[[Image], object]] = None,
) -> Union[Image, RenderState]:
    """Renders ``scene`` (see :func:`prism_renderer.render`, whose keywords ``settings``
    holds); ``progress`` and ``preview`` are callables or None. The image, or with a
    ``sample_range`` the render's state."""

def compare(
    test: Union[Image, str, os.PathLike],
    reference: Union[Image, str, os.PathLike],
    channels: Optional[List[str]] = None,
    diff: Optional[Union[str, os.PathLike]] = None,
) -> Comparison:
    """``prism compare``'s statistics of ``test`` against ``reference``; with ``diff``, the
    false-colour difference PNG written there."""

def read_image(
    path: Union[str, os.PathLike], channels: Optional[List[str]] = None
) -> npt.NDArray[np.float32]:
    """The linear values of an OpenEXR, PNG, JPEG or Radiance HDR file (see
    :func:`prism_renderer.read_image`)."""

def write_image(
    path: Union[str, os.PathLike],
    array: npt.NDArray[np.float32],
    channels: Optional[List[str]] = None,
    half: bool = False,
) -> None:
    """Writes a float32 array as OpenEXR, PNG or JPEG (see
    :func:`prism_renderer.write_image`)."""
