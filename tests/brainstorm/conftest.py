from support.fixtures import scripted_server  # noqa: F401
