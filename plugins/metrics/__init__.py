"""The built-in metrics, one module each, registered through entry points (``metric-*``) like
any third-party metric; they always load, whatever ``TSRKIT_LOAD_PLUGINS`` says."""
