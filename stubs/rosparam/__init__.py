"""Stand-in for rosparam's Python API (minros.cli.param: the code the command runs)."""

from minros.cli.param import (  # noqa: F401
    RosParamException,
    RosParamIOException,
    delete_param,
    dump_params,
    get_param,
    load_file,
    set_param,
    set_param_raw,
    upload_params,
    yamlmain,
)
from minros.cli.param import list_params_api as list_params  # noqa: F401
