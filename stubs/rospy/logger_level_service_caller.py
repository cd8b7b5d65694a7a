"""rospy.logger_level_service_caller: nodes' logger levels through their ``~get_loggers`` and
``~set_logger_level`` services (minros.cli.console)."""

from minros.cli.console import LoggerLevelServiceCaller, ROSConsoleException  # noqa: F401
