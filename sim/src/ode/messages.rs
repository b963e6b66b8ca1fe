//! ODE's error, debug and informational messages, routed through the C shim
//! of `ode-sys` into the `log` crate and a small ring of recent messages.

use std::collections::VecDeque;
use std::ffi::{c_char, c_int, CStr};
use std::sync::Mutex;

/// How many recent messages [`recent_messages`] keeps.
const RECENT_CAPACITY: usize = 64;

static RECENT: Mutex<VecDeque<OdeMessage>> = Mutex::new(VecDeque::new());

/// Which of ODE's channels a message came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OdeMessageKind {
    /// `dMessage`: informational.
    Message,
    /// `dDebug`: an internal error; ODE aborts the process right after.
    Debug,
    /// `dError`: a usage error; ODE exits the process right after.
    Error,
}

/// One message ODE printed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OdeMessage {
    /// The channel.
    pub kind: OdeMessageKind,
    /// ODE's error number.
    pub errnum: i32,
    /// The formatted text.
    pub text: String,
}

/// The most recent messages ODE emitted in this process, oldest first.
pub fn recent_messages() -> Vec<OdeMessage> {
    RECENT.lock().map(|r| r.iter().cloned().collect()).unwrap_or_default()
}

/// Installs the sink as ODE's handler for all three channels.
pub(super) fn install() {
    // SAFETY: `sink` has the exact C signature the shim expects, never
    // unwinds (it catches nothing that could panic but a poisoned lock,
    // which it tolerates), and lives for the whole program.
    unsafe { ode_sys::psa_ode_install_handlers(Some(sink)) };
}

unsafe extern "C" fn sink(kind: c_int, errnum: c_int, text: *const c_char) {
    let text = if text.is_null() {
        String::new()
    } else {
        // SAFETY: the shim passes a NUL-terminated buffer that stays valid
        // for the duration of this call.
        unsafe { CStr::from_ptr(text) }.to_string_lossy().into_owned()
    };
    let kind = match kind as u32 {
        ode_sys::psa_ode_message_kind_PSA_ODE_DEBUG => OdeMessageKind::Debug,
        ode_sys::psa_ode_message_kind_PSA_ODE_ERROR => OdeMessageKind::Error,
        _ => OdeMessageKind::Message,
    };
    match kind {
        OdeMessageKind::Message => log::warn!(target: "ode", "ODE message {errnum}: {text}"),
        OdeMessageKind::Debug | OdeMessageKind::Error => {
            // ODE terminates the process after this call: make sure the
            // reason reaches the user even without a logger.
            log::error!(target: "ode", "ODE fatal error {errnum}: {text}");
            eprintln!("psa-esp: fatal ODE error {errnum}: {text}");
        }
    }
    if let Ok(mut recent) = RECENT.lock() {
        if recent.len() == RECENT_CAPACITY {
            recent.pop_front();
        }
        recent.push_back(OdeMessage { kind, errnum, text });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ode_messages_reach_rust_as_formatted_strings() {
        super::super::ensure_thread_ready().unwrap();
        // SAFETY: dMessage is ODE's printf-style message function; the
        // format string consumes exactly the one int passed.
        unsafe { ode_sys::dMessage(7, c"shim test %d".as_ptr(), 42 as c_int) };
        let found = recent_messages()
            .into_iter()
            .any(|m| m.kind == OdeMessageKind::Message && m.errnum == 7 && m.text == "shim test 42");
        assert!(found, "message not forwarded: {:?}", recent_messages());
    }
}
