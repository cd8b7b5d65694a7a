"""Stand-in for rosparam's Python API (minros.cli.param: the code the command runs)."""

from minros.cli.param import (  # noqa: F401
    NAME,
    NS,
    RosParamException,
    RosParamIOException,
    construct_angle_degrees,
    construct_angle_radians,
    construct_yaml_binary,
    delete_param,
    dump_params,
    get_param,
    get_param_server,
    load_file,
    load_str,
    print_params,
    represent_foo,
    represent_xml_binary,
    set_param,
    set_param_raw,
    upload_params,
    yamlmain,
)
from minros.cli.param import list_params_api as list_params  # noqa: F401
from minros.names import (  # noqa: F401 - rosparam's module imports them from rosgraph.names
    GLOBALNS,
    get_ros_namespace,
    make_caller_id,
    make_global_ns,
    ns_join,
    script_resolve_name,
)
