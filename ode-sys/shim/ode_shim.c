/* Turns ODE's printf-style message callbacks into plain strings for Rust. */
#include <stdarg.h>
#include <stdio.h>
#include <ode/error.h>
#include "ode_shim.h"

static psa_ode_sink current_sink = 0;

static void forward(int kind, int errnum, const char *msg, va_list ap) {
    char text[1024];
    vsnprintf(text, sizeof text, msg ? msg : "(null)", ap);
    if (current_sink) {
        current_sink(kind, errnum, text);
    } else {
        fprintf(stderr, "ODE (%d): %s\n", errnum, text);
    }
}

static void on_message(int errnum, const char *msg, va_list ap) { forward(PSA_ODE_MESSAGE, errnum, msg, ap); }
static void on_debug(int errnum, const char *msg, va_list ap) { forward(PSA_ODE_DEBUG, errnum, msg, ap); }
static void on_error(int errnum, const char *msg, va_list ap) { forward(PSA_ODE_ERROR, errnum, msg, ap); }

void psa_ode_install_handlers(psa_ode_sink sink) {
    current_sink = sink;
    dSetMessageHandler(on_message);
    dSetDebugHandler(on_debug);
    dSetErrorHandler(on_error);
}
