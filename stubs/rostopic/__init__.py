"""Stand-in for rostopic's Python API (minros.cli.topic_api: the code the command runs)."""

from minros.cli.topic_api import (  # noqa: F401
    NAME,
    SUBSCRIBER_TIMEOUT,
    CallbackEcho,
    ROSTopicBandwidth,
    ROSTopicDelay,
    ROSTopicException,
    ROSTopicHz,
    ROSTopicIOException,
    argv_publish,
    create_field_filter,
    create_publisher,
    create_value_transform,
    file_yaml_arg,
    find_by_type,
    get_api,
    get_info_text,
    get_topic_class,
    get_topic_type,
    msgevalgen,
    param_publish,
    param_publish_once,
    publish_message,
    rostopicmain,
    stdin_publish,
    stdin_yaml_arg,
    wait_for_subscriber,
)
from minros.cli.topic_api import check_master_api as _check_master  # noqa: F401
from minros.cli.topic_api import get_nested_attribute as _get_nested_attribute  # noqa: F401
from minros.cli.topic_api import get_topic_list_api as get_topic_list  # noqa: F401
from minros.cli.topic_api import get_topic_type_now as _get_topic_type  # noqa: F401
from minros.cli.topic_api import master_get_topic_types_api as _master_get_topic_types  # noqa: F401
from minros.cli.topic_api import str_plot as _str_plot  # noqa: F401
from minros.cli.topic_api import str_plot_fields as _str_plot_fields  # noqa: F401
