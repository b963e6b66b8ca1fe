#ifndef PSA_ODE_SHIM_H
#define PSA_ODE_SHIM_H

/* Which of ODE's three message channels a message came from. */
enum psa_ode_message_kind {
    PSA_ODE_MESSAGE = 0, /* dMessage: informational */
    PSA_ODE_DEBUG = 1,   /* dDebug: internal error, ODE aborts afterwards */
    PSA_ODE_ERROR = 2    /* dError: user error, ODE exits afterwards */
};

/* Receives one fully formatted, NUL-terminated message. */
typedef void (*psa_ode_sink)(int kind, int errnum, const char *text);

/* Installs the sink as ODE's error, debug and message handler. */
void psa_ode_install_handlers(psa_ode_sink sink);

#endif
