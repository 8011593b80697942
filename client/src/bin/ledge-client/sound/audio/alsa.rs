//! ALSA, loaded at run time.
//!
//! The client links no audio library: `libasound.so.2` is opened with
//! `dlopen` when sound starts, so the build needs no `libasound2-dev` and a
//! machine without ALSA (or without a sound card: containers, CI, Xvfb)
//! simply has no sound. Only ALSA's "simple" PCM API is used:
//! `snd_pcm_open`, `snd_pcm_set_params`, `snd_pcm_writei`, `snd_pcm_wait`,
//! `snd_pcm_recover`, `snd_pcm_drop`, `snd_pcm_close` and `snd_strerror`,
//! plus `snd_lib_error_set_local` (if present) so that ALSA's own error
//! messages ("cannot find card '0'", eight lines on a machine without a
//! sound card) go to the log at debug level instead of stderr. Their C
//! declarations (`alsa/pcm.h`, `alsa/error.h`) are reproduced on each
//! function pointer type below.
//!
//! Every symbol is resolved before any is called: a library missing one is
//! an [`AlsaError::Symbol`], never a call through a bad pointer. The
//! library is never unloaded (ALSA loads plugins of its own, which may keep
//! pointers into it); one handle per successful [`open`] stays mapped for
//! the life of the process.

use std::ffi::{c_char, c_int, c_long, c_uint, c_ulong, c_void, CStr, CString};
use std::fmt;
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicBool, Ordering};

use libloading::Library;

/// The library [`open`] loads by default.
pub const LIBRARY: &str = "libasound.so.2";

/// The PCM device [`Alsa::open_pcm`] opens by default.
pub const DEFAULT_DEVICE: &str = "default";

/// `snd_pcm_stream_t`: `SND_PCM_STREAM_PLAYBACK`.
const SND_PCM_STREAM_PLAYBACK: c_int = 0;
/// `snd_pcm_open` mode: `SND_PCM_NONBLOCK` (neither opening nor writing
/// waits for the device; writes wait in `snd_pcm_wait`, with a timeout).
const SND_PCM_NONBLOCK: c_int = 1;
/// `snd_pcm_format_t`: `SND_PCM_FORMAT_S16_LE`.
const SND_PCM_FORMAT_S16_LE: c_int = 2;
/// `snd_pcm_access_t`: `SND_PCM_ACCESS_RW_INTERLEAVED`.
const SND_PCM_ACCESS_RW_INTERLEAVED: c_int = 3;
/// `-EAGAIN` on Linux (the only system with ALSA).
const EAGAIN: c_int = 11;

/// Longest wait for the device to take more samples, ms (so a stop request
/// is seen at least this often).
const WAIT_MS: c_int = 20;

/// `snd_pcm_t`: opaque.
#[repr(C)]
struct SndPcm {
    _opaque: [u8; 0],
}

/// `int snd_pcm_open(snd_pcm_t **pcm, const char *name, snd_pcm_stream_t stream, int mode)`
type PcmOpen = unsafe extern "C" fn(*mut *mut SndPcm, *const c_char, c_int, c_int) -> c_int;
/// `int snd_pcm_set_params(snd_pcm_t *pcm, snd_pcm_format_t format, snd_pcm_access_t access,
///  unsigned int channels, unsigned int rate, int soft_resample, unsigned int latency)`
type PcmSetParams =
    unsafe extern "C" fn(*mut SndPcm, c_int, c_int, c_uint, c_uint, c_int, c_uint) -> c_int;
/// `snd_pcm_sframes_t snd_pcm_writei(snd_pcm_t *pcm, const void *buffer, snd_pcm_uframes_t size)`
/// (`snd_pcm_sframes_t` is `long`, `snd_pcm_uframes_t` is `unsigned long`).
type PcmWritei = unsafe extern "C" fn(*mut SndPcm, *const c_void, c_ulong) -> c_long;
/// `int snd_pcm_wait(snd_pcm_t *pcm, int timeout)`
type PcmWait = unsafe extern "C" fn(*mut SndPcm, c_int) -> c_int;
/// `int snd_pcm_recover(snd_pcm_t *pcm, int err, int silent)`
type PcmRecover = unsafe extern "C" fn(*mut SndPcm, c_int, c_int) -> c_int;
/// `int snd_pcm_drop(snd_pcm_t *pcm)` and `int snd_pcm_close(snd_pcm_t *pcm)`
type PcmUnary = unsafe extern "C" fn(*mut SndPcm) -> c_int;
/// `const char *snd_strerror(int errnum)`
type StrError = unsafe extern "C" fn(c_int) -> *const c_char;
/// `typedef void (*snd_local_error_handler_t)(const char *file, int line,
///  const char *func, int errcode, const char *fmt, va_list arg)`.
///
/// `va_list` is passed as one pointer-sized argument on every Linux ABI
/// (an array that decays to a pointer on x86-64, a pointer on i686,
/// riscv and powerpc, a struct passed by reference on aarch64 and s390x,
/// a one-pointer struct on arm); it is the last argument and never read.
type LocalErrorHandler =
    unsafe extern "C" fn(*const c_char, c_int, *const c_char, c_int, *const c_char, *mut c_void);
/// `snd_local_error_handler_t snd_lib_error_set_local(snd_local_error_handler_t func)`
/// (thread-local; deprecated since alsa-lib 1.2.15 but still honoured).
type ErrorSetLocal = unsafe extern "C" fn(Option<LocalErrorHandler>) -> Option<LocalErrorHandler>;

/// What went wrong with ALSA. The text is meant for a log line and for the
/// window's "no sound because ..." note.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AlsaError {
    /// The library could not be loaded (not installed, usually).
    Library {
        /// The file name given to `dlopen`.
        name: String,
        /// The loader's message.
        reason: String,
    },
    /// The library lacks a function this backend needs.
    Symbol {
        /// The library.
        library: String,
        /// The missing function.
        symbol: &'static str,
    },
    /// An ALSA call failed.
    Call {
        /// Which call (and on which device).
        call: String,
        /// Its negative error code.
        code: i32,
        /// `snd_strerror` of the code.
        message: String,
    },
}

impl fmt::Display for AlsaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AlsaError::Library { name, reason } => {
                write!(f, "ALSA library {name} could not be loaded: {reason}")
            }
            AlsaError::Symbol { library, symbol } => {
                write!(f, "ALSA library {library} has no {symbol}")
            }
            AlsaError::Call {
                call,
                code,
                message,
            } => write!(f, "{call} failed: {message} ({code})"),
        }
    }
}

impl std::error::Error for AlsaError {}

/// A loaded ALSA library: every function this backend calls, resolved.
pub struct Alsa {
    name: String,
    pcm_open: PcmOpen,
    pcm_set_params: PcmSetParams,
    pcm_writei: PcmWritei,
    pcm_wait: PcmWait,
    pcm_recover: PcmRecover,
    pcm_drop: PcmUnary,
    pcm_close: PcmUnary,
    strerror: StrError,
    /// Optional: older or newer libraries may lack it.
    error_set_local: Option<ErrorSetLocal>,
    /// Kept mapped forever (see the module's documentation): the function
    /// pointers above point into it.
    _lib: ManuallyDrop<Library>,
}

impl fmt::Debug for Alsa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Alsa").field("name", &self.name).finish()
    }
}

/// Loads the ALSA library `name` (normally [`LIBRARY`]) and resolves every
/// function the backend needs. Fails cleanly (no call is made) if the
/// library or any function is missing; the error names the library.
pub fn open(name: &str) -> Result<Alsa, AlsaError> {
    // SAFETY: loading a shared library runs its initialisers. libasound's
    // are ALSA's own (no global state a Rust program relies on). A library
    // of another name given here is the caller's choice; the tests only
    // pass names that do not exist.
    let lib = unsafe { Library::new(name) }.map_err(|e| AlsaError::Library {
        name: name.to_owned(),
        reason: e.to_string(),
    })?;
    let lib = ManuallyDrop::new(lib);
    macro_rules! symbol {
        ($name:literal, $ty:ty) => {{
            // SAFETY: the type is the function's C declaration, quoted on
            // the type alias (checked against ALSA's headers). The copied
            // pointer stays valid: the library is never unloaded
            // (ManuallyDrop, kept in the returned value).
            let sym = unsafe { lib.get::<$ty>(concat!($name, "\0").as_bytes()) };
            match sym {
                Ok(sym) => *sym,
                Err(_) => {
                    return Err(AlsaError::Symbol {
                        library: name.to_owned(),
                        symbol: $name,
                    })
                }
            }
        }};
    }
    Ok(Alsa {
        name: name.to_owned(),
        pcm_open: symbol!("snd_pcm_open", PcmOpen),
        pcm_set_params: symbol!("snd_pcm_set_params", PcmSetParams),
        pcm_writei: symbol!("snd_pcm_writei", PcmWritei),
        pcm_wait: symbol!("snd_pcm_wait", PcmWait),
        pcm_recover: symbol!("snd_pcm_recover", PcmRecover),
        pcm_drop: symbol!("snd_pcm_drop", PcmUnary),
        pcm_close: symbol!("snd_pcm_close", PcmUnary),
        strerror: symbol!("snd_strerror", StrError),
        // SAFETY: as in `symbol!`; the type is the C declaration quoted on
        // `ErrorSetLocal`. Missing is fine (None).
        error_set_local: unsafe { lib.get::<ErrorSetLocal>(b"snd_lib_error_set_local\0") }
            .ok()
            .map(|sym| *sym),
        _lib: lib,
    })
}

impl Alsa {
    /// Sends ALSA's error messages raised on the calling thread to the log
    /// (debug level) instead of stderr. A no-op if the library lacks
    /// `snd_lib_error_set_local`.
    pub fn log_errors_on_this_thread(&self) {
        if let Some(set_local) = self.error_set_local {
            // SAFETY: `log_error` has the handler's C signature (see
            // `LocalErrorHandler`), never unwinds (it only reads strings and
            // logs) and lives as long as the program; the setting is
            // thread-local, so no other thread's ALSA use is affected.
            unsafe { set_local(Some(log_error)) };
        }
    }

    /// ALSA's text for an error code.
    fn strerror(&self, code: c_int) -> String {
        // SAFETY: snd_strerror accepts any int and returns a pointer to a
        // static NUL-terminated string (or, defensively, null: checked).
        let ptr = unsafe { (self.strerror)(code) };
        if ptr.is_null() {
            return format!("error {code}");
        }
        // SAFETY: non-null, NUL-terminated, static (ALSA's string table or
        // libc's strerror buffer); copied out at once.
        unsafe { CStr::from_ptr(ptr) }
            .to_string_lossy()
            .into_owned()
    }

    fn error(&self, call: String, code: c_int) -> AlsaError {
        AlsaError::Call {
            call,
            code,
            message: self.strerror(code),
        }
    }

    /// Opens `device` (normally [`DEFAULT_DEVICE`]) for playback, mono
    /// signed 16-bit at `rate` Hz, with about `latency_us` of buffering
    /// (ALSA resamples if the device needs it). Non-blocking: a device that
    /// is busy or missing is an error at once.
    pub fn open_pcm(&self, device: &str, rate: u32, latency_us: u32) -> Result<Pcm<'_>, AlsaError> {
        let c_device = CString::new(device).map_err(|_| AlsaError::Call {
            call: format!("snd_pcm_open({device:?})"),
            code: -22,
            message: "device name contains NUL".to_owned(),
        })?;
        let mut raw: *mut SndPcm = std::ptr::null_mut();
        // SAFETY: `raw` is a valid out-pointer, `c_device` a NUL-terminated
        // string alive for the call; stream and mode are valid constants.
        let rc = unsafe {
            (self.pcm_open)(
                &raw mut raw,
                c_device.as_ptr(),
                SND_PCM_STREAM_PLAYBACK,
                SND_PCM_NONBLOCK,
            )
        };
        if rc < 0 || raw.is_null() {
            let code = if rc < 0 { rc } else { -22 };
            return Err(self.error(format!("snd_pcm_open({device:?})"), code));
        }
        // From here the handle is owned: dropping `pcm` closes it.
        let pcm = Pcm {
            alsa: self,
            raw,
            device: device.to_owned(),
        };
        // SAFETY: `raw` is an open PCM handle (snd_pcm_open succeeded);
        // every other argument is a plain value of the declared type.
        let rc = unsafe {
            (self.pcm_set_params)(
                raw,
                SND_PCM_FORMAT_S16_LE,
                SND_PCM_ACCESS_RW_INTERLEAVED,
                1,
                rate,
                1,
                latency_us,
            )
        };
        if rc < 0 {
            return Err(self.error(format!("snd_pcm_set_params({device:?})"), rc));
        }
        Ok(pcm)
    }
}

/// An open playback PCM (mono, signed 16-bit), closed when dropped.
pub struct Pcm<'a> {
    alsa: &'a Alsa,
    raw: *mut SndPcm,
    device: String,
}

impl fmt::Debug for Pcm<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Pcm").field("device", &self.device).finish()
    }
}

impl Pcm<'_> {
    /// The device's name as opened.
    pub fn device(&self) -> &str {
        &self.device
    }

    /// Writes all of `samples`, waiting (20 ms at a time) while the device's
    /// buffer is full and recovering from underruns. Returns early, without
    /// error, once `stop` is set. `Ok(true)` if the device made it wait (a
    /// real device does whenever its buffer is full; ALSA's `null` device
    /// never does).
    pub fn write(&mut self, samples: &[i16], stop: &AtomicBool) -> Result<bool, AlsaError> {
        let mut waited = false;
        let mut done = 0usize;
        while done < samples.len() {
            if stop.load(Ordering::Relaxed) {
                return Ok(waited);
            }
            let rest = &samples[done..];
            // SAFETY: `raw` is open; the pointer and the frame count
            // describe `rest`, which outlives the call (mono: one i16 per
            // frame, the format set in open_pcm).
            let rc = unsafe {
                (self.alsa.pcm_writei)(self.raw, rest.as_ptr().cast(), rest.len() as c_ulong)
            };
            if rc > 0 {
                done += usize::try_from(rc).unwrap_or(0).min(rest.len());
                continue;
            }
            let code = c_int::try_from(rc).unwrap_or(c_int::MIN);
            if code == 0 || code == -EAGAIN {
                waited = true;
                self.wait()?;
                continue;
            }
            self.recover(code, "snd_pcm_writei")?;
        }
        Ok(waited)
    }

    /// Waits until the device takes more samples, at most [`WAIT_MS`].
    fn wait(&mut self) -> Result<(), AlsaError> {
        // SAFETY: `raw` is open; the timeout is a plain int (ms).
        let rc = unsafe { (self.alsa.pcm_wait)(self.raw, WAIT_MS) };
        if rc < 0 {
            self.recover(rc, "snd_pcm_wait")?;
        }
        Ok(())
    }

    /// `snd_pcm_recover` after an underrun (-EPIPE), a suspend (-ESTRPIPE)
    /// or an interrupted call; other errors are returned.
    fn recover(&mut self, code: c_int, call: &str) -> Result<(), AlsaError> {
        // SAFETY: `raw` is open; `code` is the error ALSA just returned;
        // silent = 1 (no message on stderr).
        let rc = unsafe { (self.alsa.pcm_recover)(self.raw, code, 1) };
        if rc >= 0 {
            Ok(())
        } else if rc == -EAGAIN {
            // Resuming after a suspend is not done yet: wait, retry.
            std::thread::sleep(std::time::Duration::from_millis(WAIT_MS as u64));
            Ok(())
        } else {
            Err(self.alsa.error(format!("{call}({:?})", self.device), code))
        }
    }
}

impl Drop for Pcm<'_> {
    fn drop(&mut self) {
        // SAFETY: `raw` is an open handle. Dropping its pending samples
        // first means closing never waits for them to play.
        unsafe { (self.alsa.pcm_drop)(self.raw) };
        // SAFETY: `raw` is an open handle, closed once: `self` is never
        // used again.
        unsafe { (self.alsa.pcm_close)(self.raw) };
    }
}

/// ALSA's local error handler: one debug log line per message, with the
/// message's format string as is (its arguments, in the `va_list`, are not
/// read: formatting them would need C's `vsnprintf`).
unsafe extern "C" fn log_error(
    file: *const c_char,
    line: c_int,
    function: *const c_char,
    errcode: c_int,
    fmt: *const c_char,
    _args: *mut c_void,
) {
    let text = |ptr: *const c_char| {
        if ptr.is_null() {
            String::new()
        } else {
            // SAFETY: ALSA passes NUL-terminated strings (`__FILE__`,
            // `__func__` and a literal format), valid during the call;
            // copied out at once.
            unsafe { CStr::from_ptr(ptr) }
                .to_string_lossy()
                .into_owned()
        }
    };
    tracing::debug!(
        "ALSA {}:{} ({}): {} [{}]",
        text(file),
        line,
        text(function),
        text(fmt),
        errcode
    );
}
