//! A rendered image as numpy arrays, written as OpenEXR or PNG and shown by notebooks, and the
//! comparison of two images (`prism compare`'s statistics).

use std::path::PathBuf;

use numpy::ndarray::{Array2, Array3, Dimension};
use numpy::{
    IntoPyArray, PyArray, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray2,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::error::{IntoPyResult, to_py};
use prism_core::error::{Error, ErrorKind};
use prism_core::film::output::IMAGE_CHANNELS;
use prism_core::film::{FilmImages, RenderMetadata};
use prism_core::image::compare as stats;
use prism_core::image::{ChannelImage, ExrHeader, read_exr, read_exr_with_header, write_exr_with};

/// A rendered image: H × W × 3 float32 arrays `rgb` (linear sRGB), `xyz` (CIE 1931) and
/// `variance` (the estimated variance of each pixel's mean of X, Y and Z), the H × W array
/// `relative_error` (each pixel's relative standard error of luminance), and `aovs`, the
/// integrator's extra channels (`aov`, `moment`) by their EXR names as H × W float32 arrays.
/// The arrays are the render's own memory (no copy); `write` and `_repr_png_` use their
/// current values. `numpy.asarray(image)` is `rgb`.
#[pyclass(module = "prism_renderer", frozen)]
pub struct Image {
    #[pyo3(get)]
    rgb: Py<PyArray3<f32>>,
    #[pyo3(get)]
    xyz: Py<PyArray3<f32>>,
    #[pyo3(get)]
    variance: Py<PyArray3<f32>>,
    #[pyo3(get)]
    relative_error: Py<PyArray2<f32>>,
    #[pyo3(get)]
    aovs: Py<PyDict>,
    /// Samples per pixel taken.
    #[pyo3(get)]
    spp: u32,
    /// The render's duration in seconds (as its EXR records it for an image read from a file;
    /// 0 where it records none).
    #[pyo3(get)]
    seconds: f64,
    /// The seed of the render's random numbers (None for an image read from a file that does
    /// not record it).
    #[pyo3(get)]
    seed: Option<u64>,
}

impl Image {
    /// The image of `images` and the extra channels `aovs` (name, one value per pixel), which
    /// the arrays take over, rendered with `metadata`'s samples per pixel, seed and time.
    pub fn new(
        py: Python<'_>,
        images: FilmImages,
        aovs: Vec<(String, Vec<f32>)>,
        metadata: Option<RenderMetadata>,
    ) -> PyResult<Image> {
        let (h, w) = (images.height, images.width);
        let one = |values: Vec<f32>| {
            Array2::from_shape_vec((h, w), values)
                .expect("each channel holds one value per pixel")
                .into_pyarray(py)
        };
        let channels = PyDict::new(py);
        for (name, values) in aovs {
            channels.set_item(name, one(values))?;
        }
        let three = |values: Vec<f32>| {
            Array3::from_shape_vec((h, w, 3), values)
                .expect("FilmImages holds three values per pixel")
                .into_pyarray(py)
                .unbind()
        };
        Ok(Image {
            rgb: three(images.rgb),
            xyz: three(images.xyz),
            variance: three(images.variance),
            relative_error: one(images.relative_error).unbind(),
            aovs: channels.unbind(),
            spp: metadata.map_or(0, |m| m.spp),
            seconds: metadata.and_then(|m| m.seconds).unwrap_or(0.0),
            seed: metadata.map(|m| m.seed),
        })
    }

    /// The samples per pixel, seed and time the EXR's header records, where the seed is known.
    fn metadata(&self) -> Option<RenderMetadata> {
        self.seed.map(|seed| RenderMetadata {
            spp: self.spp,
            seed,
            seconds: Some(self.seconds),
        })
    }

    /// Every array as named EXR channels: those of [`FilmImages::channels`], then the extra
    /// channels. An extra channel that is no longer an H × W float32 array is an error.
    fn channels(&self, py: Python<'_>) -> PyResult<ChannelImage> {
        let mut image = self.images(py).channels();
        for (name, values) in self.aovs.bind(py).iter() {
            let name: String = name
                .extract()
                .map_err(|_| to_py(py, &Error::usage("the names in Image.aovs must be strings")))?;
            let array: PyReadonlyArray2<'_, f32> = values.extract().map_err(|_| {
                to_py(
                    py,
                    &Error::usage(format!("Image.aovs[\"{name}\"] is not a 2-D float32 array")),
                )
            })?;
            if array.shape() != [image.height, image.width] {
                return Err(to_py(
                    py,
                    &Error::usage(format!(
                        "Image.aovs[\"{name}\"] has shape {:?}, the image {} × {}",
                        array.shape(),
                        image.height,
                        image.width
                    )),
                ));
            }
            let values = array.as_array().iter().copied().collect();
            image.channels.push((name, values));
        }
        Ok(image)
    }

    /// The arrays' current values.
    fn images(&self, py: Python<'_>) -> FilmImages {
        let shape = self.rgb.bind(py).shape();
        FilmImages {
            width: shape[1],
            height: shape[0],
            rgb: values(self.rgb.bind(py)),
            xyz: values(self.xyz.bind(py)),
            variance: values(self.variance.bind(py)),
            relative_error: values(self.relative_error.bind(py)),
        }
    }
}

#[pymethods]
impl Image {
    /// Reads an OpenEXR image that Prism wrote with the film's default `pixel_format` `rgb`
    /// (channels R, G, B, X, Y, Z, variance.X/Y/Z and relative_error.Y, 32-bit or half), with
    /// the samples per pixel, seed and time its header records; its other channels are the
    /// `aovs`.
    #[staticmethod]
    fn read(py: Python<'_>, path: PathBuf) -> PyResult<Image> {
        let (exr, header) = py
            .detach(|| read_exr_with_header(&path).map_err(as_input_error))
            .into_py_result(py)?;
        let images = FilmImages::from_channels(&exr).map_err(|missing| {
            to_py(
                py,
                &Error::usage(format!("\"{}\" has no channel {missing}", path.display()))
                    .with_help(
                        "read an image that Prism rendered with pixel_format rgb; \
                         read_image() and compare() read any EXR",
                    ),
            )
        })?;
        let aovs = exr
            .channels
            .into_iter()
            .filter(|(name, _)| !IMAGE_CHANNELS.contains(&name.as_str()))
            .collect();
        Image::new(py, images, aovs, RenderMetadata::of(&header))
    }

    /// The `rgb` array (`numpy.asarray(image)`), converted to `dtype` or copied where asked.
    #[pyo3(signature = (dtype = None, copy = None))]
    fn __array__<'py>(
        &self,
        py: Python<'py>,
        dtype: Option<Bound<'py, PyAny>>,
        copy: Option<bool>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rgb = self.rgb.bind(py).clone().into_any();
        match (dtype, copy) {
            (None, None | Some(false)) => Ok(rgb),
            (dtype, _) => {
                let dtype = match dtype {
                    Some(dtype) => dtype,
                    None => rgb.getattr("dtype")?,
                };
                rgb.call_method1("astype", (dtype,))
            }
        }
    }

    /// The width in pixels.
    #[getter]
    fn width(&self, py: Python<'_>) -> usize {
        self.rgb.bind(py).shape()[1]
    }

    /// The height in pixels.
    #[getter]
    fn height(&self, py: Python<'_>) -> usize {
        self.rgb.bind(py).shape()[0]
    }

    /// Writes the image: `.exr` gives OpenEXR with every array as channels, the `aovs` under
    /// their names (as `prism render` writes), `.png` the RGB image as 8-bit sRGB.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let result = match extension.as_deref() {
            Some("exr") => {
                let image = self.channels(py)?;
                let header = ExrHeader {
                    half_channels: Vec::new(),
                    attributes: self.metadata().map(|m| m.attributes()).unwrap_or_default(),
                };
                py.detach(|| write_exr_with(&path, &image, &header))
            }
            Some("png") => {
                let images = self.images(py);
                py.detach(|| images.write_png(&path))
            }
            _ => Err(Error::usage(format!(
                "cannot write \"{}\": the name must end in .exr or .png",
                path.display()
            ))),
        };
        result.into_py_result(py)
    }

    /// The RGB image as the bytes of an sRGB PNG file (Jupyter shows it).
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self
            .images(py)
            .png_bytes()
            .map_err(|e| to_py(py, &Error::usage(format!("cannot encode the PNG: {e}"))))?;
        Ok(PyBytes::new(py, &bytes))
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "Image({}×{} pixels, {} spp)",
            self.width(py),
            self.height(py),
            self.spp
        )
    }
}

/// The values of `array`, in row-major order.
fn values<D: Dimension>(array: &Bound<'_, PyArray<f32, D>>) -> Vec<f32> {
    array.readonly().as_array().iter().copied().collect()
}

/// A file given to read, whose failures are the input's fault.
pub(crate) fn as_input_error(mut error: Error) -> Error {
    error.kind = ErrorKind::Input;
    error
}

/// One side of a comparison: a rendered image or the path of an EXR file.
#[derive(FromPyObject)]
pub enum Operand<'py> {
    Image(Bound<'py, Image>),
    Path(PathBuf),
}

impl Operand<'_> {
    fn channels(&self, py: Python<'_>) -> PyResult<ChannelImage> {
        match self {
            Operand::Image(image) => image.get().channels(py),
            Operand::Path(path) => py
                .detach(|| read_exr(path).map_err(as_input_error))
                .into_py_result(py),
        }
    }
}

/// Compares a test image with a reference, each an `Image` or the path of an EXR file, on
/// `channels` (default: R, G, B if both have them, else X, Y, Z): `prism compare`'s
/// statistics, with the z-test where the test image has variances; with `diff`, writes the
/// false-colour difference PNG there, as `prism compare --diff`.
#[pyfunction]
#[pyo3(signature = (test, reference, channels = None, diff = None))]
pub fn compare(
    py: Python<'_>,
    test: Operand<'_>,
    reference: Operand<'_>,
    channels: Option<Vec<String>>,
    diff: Option<PathBuf>,
) -> PyResult<Comparison> {
    let test = test.channels(py)?;
    let reference = reference.channels(py)?;
    let comparison = stats::compare(&test, &reference, channels.as_deref()).into_py_result(py)?;
    if let Some(path) = diff {
        py.detach(|| stats::write_difference_png(&test, &reference, &comparison, &path))
            .into_py_result(py)?;
    }
    Ok(Comparison { comparison })
}

/// The outcome of `compare`; `str()` gives the table `prism compare` prints.
#[pyclass(module = "prism_renderer", frozen)]
pub struct Comparison {
    comparison: stats::Comparison,
}

#[pymethods]
impl Comparison {
    /// Per compared channel: means, MSE, relative MSE, largest difference.
    #[getter]
    fn channels(&self) -> Vec<ChannelDifference> {
        self.comparison
            .channels
            .iter()
            .map(|d| ChannelDifference {
                difference: d.clone(),
            })
            .collect()
    }

    /// The MSE averaged over the channels.
    #[getter]
    fn mse(&self) -> f64 {
        self.comparison.mse()
    }

    /// The relative MSE, (a − b)² / (b² + 0.01), averaged over the channels.
    #[getter]
    fn rel_mse(&self) -> f64 {
        self.comparison.rel_mse()
    }

    /// The per-pixel z-test of luminance, or None when the test image has no variances.
    #[getter]
    fn z_test(&self) -> Option<ZTest> {
        self.comparison.z_test.clone().map(|test| ZTest { test })
    }

    fn __str__(&self) -> String {
        self.comparison.to_string()
    }

    fn __repr__(&self) -> String {
        format!(
            "Comparison(rel_mse={:.4e}, consistent_with_noise={})",
            self.rel_mse(),
            match &self.comparison.z_test {
                Some(z) =>
                    if z.consistent_with_noise() {
                        "True"
                    } else {
                        "False"
                    },
                None => "None",
            }
        )
    }
}

/// How one channel of two images differs.
#[pyclass(module = "prism_renderer", frozen)]
pub struct ChannelDifference {
    difference: stats::ChannelDifference,
}

#[pymethods]
impl ChannelDifference {
    #[getter]
    fn name(&self) -> &str {
        &self.difference.name
    }
    #[getter]
    fn mean_test(&self) -> f64 {
        self.difference.mean_test
    }
    #[getter]
    fn mean_reference(&self) -> f64 {
        self.difference.mean_reference
    }
    #[getter]
    fn mse(&self) -> f64 {
        self.difference.mse
    }
    #[getter]
    fn rel_mse(&self) -> f64 {
        self.difference.rel_mse
    }
    #[getter]
    fn max_abs(&self) -> f64 {
        self.difference.max_abs
    }

    fn __repr__(&self) -> String {
        format!(
            "ChannelDifference(name={:?}, mean_test={}, mean_reference={}, rel_mse={:.4e})",
            self.difference.name,
            self.difference.mean_test,
            self.difference.mean_reference,
            self.difference.rel_mse
        )
    }
}

/// The per-pixel z-test zᵢ = (aᵢ − bᵢ)/√(σ²_a + σ²_b) of luminance.
#[pyclass(module = "prism_renderer", frozen)]
pub struct ZTest {
    test: stats::ZTest,
}

#[pymethods]
impl ZTest {
    /// Pixels tested.
    #[getter]
    fn pixels(&self) -> usize {
        self.test.pixels
    }
    /// Σ zᵢ².
    #[getter]
    fn chi2(&self) -> f64 {
        self.test.chi2
    }
    /// The p-value of `chi2` for a χ² distribution with `pixels` degrees of freedom.
    #[getter]
    fn p_value(&self) -> f64 {
        self.test.p_value
    }
    /// The largest |zᵢ|.
    #[getter]
    fn max_z(&self) -> f64 {
        self.test.max_z
    }
    /// The two-sided p-value of `max_z` times the number of pixels (Bonferroni).
    #[getter]
    fn max_z_p_value(&self) -> f64 {
        self.test.max_z_p_value
    }
    /// The fraction of pixels with |z| > 3 (0.27 % expected from noise alone).
    #[getter]
    fn beyond_three(&self) -> f64 {
        self.test.beyond_three
    }
    /// Whether both p-values exceed 0.01.
    #[getter]
    fn consistent_with_noise(&self) -> bool {
        self.test.consistent_with_noise()
    }

    fn __str__(&self) -> String {
        self.test.to_string()
    }
}
