"""Reading wire traces (``minros.wire.trace`` writes them): ``merge`` loads the files of several
processes, splits unrelated runs and joins the two views of each exchange; ``show`` prints the
sequence per topic and service, numbered as courses number it; ``pcap`` builds a capture file;
``dissector`` writes the Wireshark dissector that decodes TCPROS bodies by type. All are pure:
events in, text or bytes out."""
